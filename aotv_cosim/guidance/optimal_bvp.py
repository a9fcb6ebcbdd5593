"""Fixed-final-time minimum-effort transfer of seed 000: the 2PBVP (3.21)-(3.22).

Minimise J = int_0^tf R u^2 dt (eq. 3.2, R = 1) subject to the planar model (2.7) with the entry
state and the exit state prescribed (3.22), or with the exit speed left free, lambda_v(tf) = 0
(eq. 4.24, the variant behind eq. 4.28; extraction Sec. 4.3 and Sec. 8 item 8). The necessary
conditions (3.19)-(3.21) are solved by `scipy.integrate.solve_bvp` (collocation of the bvp4c
family the thesis used, ref. [16]).

The solver works in the thesis's km-s units, with time normalised by tf and each of the six
variables divided by a fixed scale (`_SCALE`) so that solve_bvp's residual test, which is absolute
for small derivatives, acts as a relative one on every variable. Boundary values and results are SI
at the interface; costates are reported in km-s units with R = 1 (extraction Sec. 6.1).
"""

import time
from bisect import bisect_right
from dataclasses import dataclass

import numpy as np

from aotv_cosim.physics.planar import (
    ENTRY_000, EXIT_000, K_BALL_000, TF_000, AotvConstants, augmented_dynamics, dynamics, km_state,
)

R_WEIGHT = 1.0
"""Control weight R of eq. (3.2) (Table 4.1), for u in km/s^2."""

_SCALE = np.array([1.0, 1e-2, 1e-2, 1e-6, 1e-4, 1e-2])
"""Scale of (r km, v km/s, gamma rad, lambda_r, lambda_v, lambda_gamma) in the solver's variables."""

GUESS_U0 = 0.8
"""Sec. 4.1 initial guess of the control, u = GUESS_U0 (1 - t/tf), in m/s^2."""
GUESS_LAMBDA_R = -5e-6
"""Sec. 4.1 initial guess of lambda_r (constant), km/s^3."""


class NominalSpline:
    """The solution of `solve_bvp` as a function of t (s): its C1 cubic spline (a scipy `PPoly` on
    the normalised time tau = t/tf, extrapolated beyond the mesh) times the variable scales, in
    km-s units (r, v, gamma, lambda_r, lambda_v, lambda_gamma).

    Calling it evaluates the `PPoly` on arrays. `at(t)` evaluates one time in plain floats for the
    guidance's per-step lookup, with the same operations as scipy's compiled evaluation (interval
    [x_i, x_i+1) found by bisection, the last one closed; the power sum c3 + c2 s + c1 s^2 + c0 s^3
    accumulated in that order), so both give the same numbers to the bit at a fraction of the cost.
    """

    def __init__(self, ppoly, tf: float):
        self.ppoly, self.tf = ppoly, tf
        self.breaks = ppoly.x.tolist()
        self.pieces = [[tuple(ppoly.c[::-1, i, j].tolist()) for j in range(ppoly.c.shape[2])]
                       for i in range(ppoly.c.shape[1])]
        """Per interval, per variable: coefficients (c3, c2, c1, c0) of s^0 .. s^3."""
        self.scales = _SCALE.tolist()
        self._last: tuple = (None, None)

    def __call__(self, t):
        """(6, ...) km-s values at time(s) t (s)."""
        return self.ppoly(np.asarray(t) / self.tf) * _SCALE.reshape((6,) + (1,) * np.ndim(t))

    def at(self, t: float) -> tuple:
        """The 6 km-s values at one time t (s), as floats; the last lookup is kept (the guidance
        reads the state and the control at the same t; read and replaced whole, so threads that
        share the spline see a consistent pair)."""
        last = self._last
        if last[0] == t:
            return last[1]
        tau = t / self.tf
        breaks = self.breaks
        i = min(max(bisect_right(breaks, tau) - 1, 0), len(breaks) - 2)
        s = tau - breaks[i]
        s2 = s * s
        s3 = s2 * s
        values = tuple((((0.0 + c[0]) + c[1] * s) + c[2] * s2 + c[3] * s3) * k
                       for c, k in zip(self.pieces[i], self.scales))
        self._last = (t, values)
        return values


@dataclass(frozen=True)
class MinEffortSolution:
    """Solution of the 2PBVP (3.21)-(3.22).

    t: collocation mesh, s. x: (3, n) states r (m), v (m/s), gamma (rad) on the mesh. costates:
    (3, n) lambda_r, lambda_v, lambda_gamma in km-s units with R = 1. solve_time: wall-clock time
    of the solve_bvp call, s. success/message: solve_bvp's verdict.
    """

    t: np.ndarray
    x: np.ndarray
    costates: np.ndarray
    solve_time: float
    success: bool
    message: str
    interpolant: NominalSpline
    """Maps t (s) to the (6, ...) km-s solution (r, v, gamma, lambdas), cubic between nodes."""

    def state(self, t):
        """States (r m, v m/s, gamma rad) at time(s) t (s), shape (3, ...)."""
        y = self.interpolant(t)
        return np.array([y[0] * 1e3, y[1] * 1e3, y[2]])

    def state_at(self, t: float) -> tuple:
        """`state(t)` at one time t (s) as floats (r m, v m/s, gamma rad), the same numbers."""
        y = self.interpolant.at(t)
        return y[0] * 1e3, y[1] * 1e3, y[2]

    def u_at(self, t: float) -> float:
        """`u(t)` at one time t (s) as a float in m/s^2, the same number."""
        y = self.interpolant.at(t)
        return -y[5] / (2.0 * R_WEIGHT * y[1]) * 1e3

    def costate(self, t):
        """Costates (lambda_r, lambda_v, lambda_gamma) in km-s units (R = 1) at time(s) t (s)."""
        return self.interpolant(t)[3:]

    def u(self, t):
        """Optimal lift acceleration u = -lambda_gamma/(2 R v), eq. (3.20), in m/s^2 at t (s)."""
        y = self.interpolant(t)
        return -y[5] / (2.0 * R_WEIGHT * y[1]) * 1e3

    def effort(self, n: int = 3001) -> float:
        """Cost J = int R u^2 dt of eq. (3.2) with u in m/s^2, i.e. in m^2/s^3 (Simpson, n odd)."""
        t = np.linspace(self.t[0], self.t[-1], n)
        w = np.ones(n)
        w[1:-1:2], w[2:-1:2] = 4.0, 2.0
        return float(R_WEIGHT * np.sum(w * self.u(t) ** 2) * (t[1] - t[0]) / 3.0)


def _initial_guess(tau, tf: float, x0_km, a: float, b: float, lam_r: float, c: AotvConstants):
    """Guess of Sec. 4.1 on the normalised mesh tau: states of (2.7) flown with u = a + b t
    (a, b in km/s^2, km/s^3), lambda_gamma = -2 R v u (from 3.20), lambda_r constant (km/s^3),
    lambda_v = 0. Returns the scaled (6, n) array."""
    from scipy.integrate import solve_ivp  # here: importing scipy costs a worker 0.7 s

    t = tau * tf
    fly = solve_ivp(lambda s, x: dynamics(x, a + b * s, c), (0.0, tf), x0_km, method="DOP853",
                    t_eval=t, rtol=1e-10, atol=1e-12)
    u = a + b * t
    y = np.vstack([fly.y, np.full_like(t, lam_r), np.zeros_like(t), -2.0 * R_WEIGHT * fly.y[1] * u])
    return y / _SCALE[:, None]


def solve_min_effort(entry=ENTRY_000, exit_target=EXIT_000, tf: float = TF_000,
                     k_ball: float = K_BALL_000, free_exit_velocity: bool = False,
                     guess: tuple[float, float] | None = None, tol: float = 1e-6,
                     n_nodes: int = 61) -> MinEffortSolution:
    """Solve the fixed-tf minimum-effort 2PBVP (3.21)-(3.22) by collocation.

    entry: (h0 m, v0 m/s, gamma0 rad); exit_target: (hf m, vf m/s, gammaf rad), vf ignored when
    free_exit_velocity (then lambda_v(tf) = 0, eq. 4.24); tf in s (any tf', Ch. 6); k_ball in 1/m.
    guess: optional time-linear control (a m/s^2, b m/s^3) to start from, with lambda_r = 2 R b
    (eq. 4.2 with c ~ c1); None uses the Sec. 4.1 guess u = 0.8 m/s^2 (1 - t/tf), lambda_r =
    -5e-6 km/s^3. tol: solve_bvp tolerance on the scaled residuals; n_nodes: initial mesh size.
    The reported solve_time covers the guess and the solve_bvp call.
    """
    start = time.perf_counter()
    c = AotvConstants.km(k_ball)
    x0, xf = km_state(entry), km_state(exit_target)
    if guess is None:
        a, b, lam_r = GUESS_U0, -GUESS_U0 / tf, GUESS_LAMBDA_R
    else:
        a, b = guess
        lam_r = 2.0 * R_WEIGHT * b * 1e-3
    tau = np.linspace(0.0, 1.0, n_nodes)
    scale = _SCALE[:, None]

    def rhs(_tau, z):
        return tf * augmented_dynamics(z * scale, c, R_WEIGHT) / scale

    def boundary(za, zb):
        ya, yb = za * _SCALE, zb * _SCALE
        exit_speed = yb[4] if free_exit_velocity else yb[1] - xf[1]
        res = [ya[0] - x0[0], ya[1] - x0[1], ya[2] - x0[2], yb[0] - xf[0], exit_speed, yb[2] - xf[2]]
        return np.array(res) / _SCALE[[0, 1, 2, 0, 4 if free_exit_velocity else 1, 2]]

    z0 = _initial_guess(tau, tf, x0, a * 1e-3, b * 1e-3, lam_r, c)
    from scipy.integrate import solve_bvp

    sol = solve_bvp(rhs, boundary, tau, z0, tol=tol, max_nodes=20000)
    elapsed = time.perf_counter() - start
    y = sol.y * scale
    x_si = np.array([y[0] * 1e3, y[1] * 1e3, y[2]])
    return MinEffortSolution(sol.x * tf, x_si, y[3:], elapsed, bool(sol.success), sol.message,
                             NominalSpline(sol.sol, tf))
