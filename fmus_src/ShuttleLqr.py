"""ShuttleLqr FMU: seed 003 fixed-end-point time-varying LQR elevator law (Ch. 4)."""

import math
import time

import numpy as np

from aotv_cosim.fmu import guidance_slave
from aotv_cosim.fmu.slave import POSITIVE, AotvSlave
from aotv_cosim.guidance import shuttle_lqr as lqr
from aotv_cosim.physics import shuttle_trajectory as st

LATCHED = ("h", "v", "gamma", "alpha", "alpha_prime", "xi")


class ShuttleLqr(AotvSlave):
    """Optimal law with Q = I and the printed R over a window of `window` shuttle lengths.

    At initialization it flies the nominal glide ahead of the measured state (a priori data,
    extraction A-22), and solves either the backward Riccati equation and forward co-state
    (method 0, Sec. 4.2) or the asymptotic multiple-time-scales solution (method 1, Sec. 4.3) from
    the measured X(xi0); `literal` picks the asymptotic variant (guidance.shuttle_lqr.AsymptoticLqr).
    feedback 0 flies the optimal u*(xi) open loop, as the thesis does;
    feedback 1 applies u = -R^-1 B^T K^-1(xi) X with the measured X (beyond the thesis) until
    0.98 window. After the window: delta_e = f / mu (A-15). delta_e = (f - u) / mu (4.9).
    """

    description = "Seed 003 fixed-end-point LQR elevator law (numerical or asymptotic)"
    default_step = 0.02

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.parameter("R", lqr.R_PRINTED["150kft"], "1", "Control weight R (Q = I)")
        self.parameter("window", 446.8, "1", "xi_f - xi0, shuttle lengths")
        self.integer_parameter("method", 0, "0: numerical Riccati; 1: asymptotic", min=0, max=1)
        self.integer_parameter("literal", 0, "method 1: 0 coefficients frozen at xi_f, quartic "
                               "(4.85); 1 as printed: roots of (4.82) and A follow xi", min=0, max=1)
        self.integer_parameter("feedback", 0, "0: optimal u* open loop; 1: u = -R^-1 B^T K^-1 X", min=0, max=1)
        for name, start, unit, low in (("h", st.H_START, "m", 0.0), ("v", st.V_HI, "m/s", POSITIVE),
                                       ("gamma", st.GAMMA_START, "rad", -math.pi / 2)):  # 400,000 ft entry
            self.input(name, start, unit, f"Nominal {name} (latched at start)", min=low)
        guidance_slave.declare_pitch_measurements(self, ('alpha', 'alpha_prime', 'xi', 'f', 'mu'))
        self.output("delta_e", "rad", "Commanded elevator deflection", self._command,
                    depends_on=("alpha", "alpha_prime", "xi", "f", "mu"),
                    initial_depends_on=LATCHED + ("f", "mu"))
        self.output("u_star", "1", "Optimal control u of (4.5)", lambda: self._u(),
                    depends_on=("alpha", "alpha_prime", "xi"), initial_depends_on=LATCHED)
        self.output("alpha_star", "rad", "Optimal alpha X*_1 predicted at initialization",
                    lambda: self._table(1), depends_on=("xi",), initial_depends_on=LATCHED)
        self.output("solve_time", "s", "Wall time of the solve at initialization",
                    lambda: self._solution()["solve_time"], initial_depends_on=LATCHED)
        self.latched = None
        self._cache = (None, None)

    def _solve(self):
        start = time.perf_counter()
        traj = st.predict(self.h, self.v, self.gamma, self.window)
        coeffs = st.coefficient_model(traj)
        x0 = (self.alpha, self.alpha_prime)
        grid = np.linspace(0.0, self.window, 2001)
        if self.method == 0:
            num = lqr.NumericalLqr.solve(coeffs, self.window, self.R, x0, n=grid.size)
            u, x, gain = num.u, num.x, lqr.riccati_backward(coeffs, self.window, self.R)
        else:
            literal = self.literal == 1
            asym = lqr.AsymptoticLqr.at_final(coeffs, self.window, self.R,
                                              "full" if literal else "reduced", not literal)
            u, x = asym.trajectory(x0, grid)
            gain = asym.gain
        return {"xi0": self.xi, "grid": grid, "u": u, "x": x, "gain": gain,
                "solve_time": time.perf_counter() - start}

    def _solution(self):
        if self.latched is not None:
            return self.latched
        key = tuple(getattr(self, n) for n in LATCHED + ("R", "window", "method", "literal"))
        if key != self._cache[0]:
            self._cache = (key, self._solve())
        return self._cache[1]

    def _local(self):
        sol = self._solution()
        return sol, self.xi - sol["xi0"]

    def _table(self, column):
        sol, xi = self._local()
        if xi > self.window:
            return 0.0
        return float(np.interp(xi, sol["grid"], sol["u"] if column == 0 else sol["x"][:, 0]))

    def _u(self):
        sol, xi = self._local()
        if xi > self.window:
            return 0.0
        if self.feedback == 1:
            if xi > 0.98 * self.window:
                return 0.0
            p = np.linalg.solve(sol["gain"](xi), [self.alpha, self.alpha_prime])
            return float(-p[1] / self.R)
        return self._table(0)

    def _command(self):
        return (self.f - self._u()) / self.mu

    def latch(self):
        self.latched = self._solution()

    def do_step(self, current_time, step_size):
        return True
