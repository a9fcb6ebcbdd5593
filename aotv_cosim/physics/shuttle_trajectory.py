"""Seed 003 nominal trajectory: a reconstructed shuttle-like shallow glide (extraction Sec. 4.3).

The thesis prints no trajectory (Fig. 2.3 only): 400,000 ft to 100,000 ft, Mach 24 to about 2,
alpha0 about 53 deg to about 20 deg, about 35 min, about 6000 miles. It is synthesised here by
flying the 3-D point mass of `point_mass` (the AlphaBankVehicle FMU's equations: (1.28), (1.29),
(1.32) with inverse-square gravity over a non-rotating Earth) with

- the nominal angle of attack `alpha_schedule`: linear in speed from 53 deg at 24,800 ft/s (Mach 24
  at the isothermal 1035 ft/s) to 20 deg at 2,070 ft/s (Mach 2), clamped outside;
- a bank law `lift_up_fraction` that damps the phugoid of the pull-out (the optimal trajectory is
  a shallow glide, its coefficients "almost monotonically increasing", f < 0 throughout): the
  vertical lift fraction cos(bank) makes gamma relax in TAU_GLIDE to the full-lift equilibrium
  glide slope -2 H g / (V^2 L/D), clipped to [0, 1] (lift up while the air is too thin);
- Newtonian aerodynamics (2.1)-(2.2), flown as the least-squares polynomial polar `POLAR` over
  20-53 deg (the AlphaBankVehicle FMU takes polynomial polars);
- a trajectory wing loading of 30 lbf/ft^2 on the generic 6000 ft^2 (`TRAJECTORY_MASS`), between
  the generic model's 20 psf and the orbiter's ~70 psf: with Newtonian lift it is the loading that
  reaches 100,000 ft near Mach 2.5 (extraction 4.3 asks for shuttle loading; with Newtonian lift
  70 psf reaches 100,000 ft at Mach 3.6). The trajectory mass is kept separate from the generic
  model's m used in delta, sigma and mu, as the thesis effectively does;
- entry at 400,000 ft, 24,800 ft/s, gamma = -0.6 deg.

Every choice is recorded in docs/seed003.md with the resulting figures.
"""

import math
from dataclasses import dataclass

import numpy as np

from aotv_cosim.physics import point_mass
from aotv_cosim.physics.shuttle_pitch import FT, GENERIC, PLANET, TrajectoryRates, coefficients

ALPHA_HI, ALPHA_LO = math.radians(53.0), math.radians(20.0)
"""Nominal angle of attack at the start and at the end of the glide, rad (Sec. 2.3)."""
V_HI, V_LO = 24800.0 * FT, 2070.0 * FT
"""Speeds (m/s) where the schedule reaches ALPHA_HI and ALPHA_LO (Mach 24 and 2 at 1035 ft/s)."""
H_START, H_END = 400000.0 * FT, 100000.0 * FT
"""Altitudes of the start and the end of the glide, m."""
GAMMA_START = math.radians(-0.6)
"""Flight-path angle at 400,000 ft, rad."""
TAU_GLIDE = 30.0
"""Relaxation time of gamma toward the equilibrium glide slope in the bank law, s."""
WING_LOADING = 30.0 * 47.88025898
"""Trajectory weight over area, Pa (30 lbf/ft^2)."""
TRAJECTORY_MASS = WING_LOADING * GENERIC.S / PLANET.g_s
"""Mass flying the trajectory on the generic area S, kg."""
MU_EARTH = PLANET.g_s * PLANET.R_e ** 2
"""Gravitational parameter consistent with g_s and R_e, m^3/s^2."""


def alpha_schedule(v: float, alpha_hi: float = ALPHA_HI, alpha_lo: float = ALPHA_LO,
                   v_hi: float = V_HI, v_lo: float = V_LO) -> float:
    """Nominal angle of attack alpha0 (rad) at speed v (m/s): linear in v, clamped."""
    frac = min(1.0, max(0.0, (v - v_lo) / (v_hi - v_lo)))
    return alpha_lo + (alpha_hi - alpha_lo) * frac


def lift_up_fraction(h: float, v: float, gamma: float, alpha0: float, tau: float = TAU_GLIDE,
                     mass_per_area: float = TRAJECTORY_MASS / GENERIC.S) -> float:
    """cos(bank) of the nominal glide at (h m, v m/s, gamma rad, alpha0 rad), in [0, 1].

    Solves (1.29) for the vertical lift that gives gammadot = (gamma_eq - gamma) / tau, with
    gamma_eq = -2 H g / (V^2 L/D) the equilibrium-glide slope of an exponential atmosphere.
    """
    r = PLANET.R_e + h
    g = PLANET.gravity(r)
    cl, cd = polar(alpha0)
    lift = 0.5 * PLANET.density(h) * v * v * cl / mass_per_area
    gamma_eq = -2.0 * PLANET.H * g * cd / (v * v * cl)
    need = (g - v * v / r) * math.cos(gamma) + v * (gamma_eq - gamma) / tau
    return min(1.0, max(0.0, need / lift))


def polar(alpha: float):
    """(C_L, C_D) of the fitted polar `POLAR` at alpha (rad)."""
    return (POLAR["cl0"] + POLAR["cl1"] * alpha,
            POLAR["cd0"] + (POLAR["cd1"] + POLAR["cd2"] * alpha) * alpha)


def _newtonian_polar_fit():
    alpha = np.linspace(ALPHA_LO, ALPHA_HI, 67)
    cl = 2.0 * np.sin(alpha) ** 2 * np.cos(alpha)
    cd = 2.0 * np.sin(alpha) ** 3
    cl1, cl0 = np.polyfit(alpha, cl, 1)
    cd2, cd1, cd0 = np.polyfit(alpha, cd, 2)
    return {"cl0": float(cl0), "cl1": float(cl1), "cd0": float(cd0), "cd1": float(cd1),
            "cd2": float(cd2)}


POLAR = _newtonian_polar_fit()
"""AlphaBankVehicle polar: C_L = cl0 + cl1 a, C_D = cd0 + cd1 a + cd2 a^2, least squares to
(2.1)-(2.2) over 20-53 deg (largest error 0.03 in C_L at the ends)."""


@dataclass
class Trajectory:
    """Nominal trajectory samples (SI): t s, h m, v m/s, gamma rad, alpha0 rad, xi, rho kg/m^3."""

    t: np.ndarray
    h: np.ndarray
    v: np.ndarray
    gamma: np.ndarray
    alpha0: np.ndarray
    xi: np.ndarray
    rho: np.ndarray

    def rates(self):
        """xi-rates (V'/V, gamma', theta0', theta0'') at every sample, by second-order finite
        differences in time converted with d/dxi = (L/V) d/dt (thesis Sec. 2.3.1)."""
        w = GENERIC.L / self.v
        v_dot = np.gradient(self.v, self.t)
        theta = self.gamma + self.alpha0
        theta_dot = np.gradient(theta, self.t)
        theta_dd = np.gradient(theta_dot, self.t)
        v_rel = w * v_dot / self.v
        return [TrajectoryRates(*r) for r in zip(v_rel, w * np.gradient(self.gamma, self.t),
                                                 w * theta_dot, w * w * theta_dd - v_rel * w * theta_dot)]

    def coefficients(self, **model):
        """Arrays omega0, omega1, f, mu, damping along the trajectory (dict of numpy arrays)."""
        cs = [coefficients(rho, h, v, g, a, r, **model)
              for rho, h, v, g, a, r in zip(self.rho, self.h, self.v, self.gamma, self.alpha0,
                                            self.rates())]
        return {k: np.array([getattr(c, k) for c in cs])
                for k in ("omega0", "omega1", "f", "mu", "damping", "delta")}

    def first_crossing(self, h: float) -> int:
        """Index of the first sample at or below altitude h (m)."""
        return int(np.argmax(self.h <= h))


def fly(h0: float = H_START, v0: float = V_HI, gamma0: float = GAMMA_START, dt: float = 0.5,
        h_stop: float = H_END, t_max: float = 4000.0, xi0: float = 0.0) -> Trajectory:
    """Fly the nominal glide from (h0 m, v0 m/s, gamma0 rad) by RK4 steps of dt (s), the schedule
    and the bank held over each step as the AlphaBankVehicle FMU sees them, until h <= h_stop or
    t >= t_max."""
    cl_s = GENERIC.S / TRAJECTORY_MASS
    x = [PLANET.R_e + h0, 0.0, 0.0, v0, gamma0, 0.0]
    rows = []
    t, xi = 0.0, xi0
    while True:
        h, v = x[0] - PLANET.R_e, x[3]
        alpha = alpha_schedule(v)
        rho = PLANET.density(h)
        rows.append((t, h, v, x[4], alpha, xi, rho))
        if h <= h_stop or t >= t_max - 1e-9:
            break
        cl, cd = polar(alpha)
        bank = math.acos(lift_up_fraction(h, v, x[4], alpha))
        x_new = point_mass.rk4_step(x, dt, (rho, 0.0, cl * cl_s, cd * cl_s, bank,
                                            point_mass.GRAVITY_INVERSE_SQUARE, PLANET.g_s, MU_EARTH))
        xi += 0.5 * (x[3] + x_new[3]) * dt / GENERIC.L
        x, t = x_new, t + dt
    return Trajectory(*map(np.array, zip(*rows)))


ALPHA_I = math.radians(5.0)
"""Initial perturbation alpha(xi0) of every thesis run, rad (Sec. 2.5.1); alpha'(xi0) = 0."""
DELTA_E_MAX = math.radians(25.0)
"""Elevator range, rad (Sec. 3.1.1, 4.2, 5.1.1)."""
LAMBDA_FL = {"400kft": 1.11e-4, "150kft": 1.92e-2}
"""Printed feedback-linearization gains (Sec. 3.1.1), per shuttle length."""
OMEGA_150 = (5.596e-5, 1.7698e-3)
"""omega0, omega1 at 150,000 ft inferred from the printed Sec. 4.3.4 coefficients (extraction 6.4)."""


def start_indices(trajectory: Trajectory):
    """{'400kft': 0, '150kft': first crossing of 150,000 ft} (extraction A-20)."""
    return {"400kft": 0, "150kft": trajectory.first_crossing(150000.0 * FT)}


def calibrate_moment_derivatives(trajectory: Trajectory, cm_alphadot: float = 0.0):
    """The moment derivatives (MomentDerivatives) that make, on `trajectory`,

    - omega0 and omega1 at the 150,000 ft point equal OMEGA_150 (C_malpha and C_mq, constant);
    - the feedback-linearization start demand [(lambda^2 - omega0) alpha_i + f] / mu (Sec. 5.1.1)
      equal +25 deg at both start points with the printed lambdas (C_mdeltae linear in alpha0).
    Every coefficient is affine in the derivatives, so two 2x2 linear solves give them exactly.
    """
    from aotv_cosim.physics.shuttle_pitch import MomentDerivatives, coefficients as coeffs

    rates = trajectory.rates()
    idx = start_indices(trajectory)

    def at(i, aero):
        tr = trajectory
        return coeffs(tr.rho[i], tr.h[i], tr.v[i], tr.gamma[i], tr.alpha0[i], rates[i], aero)

    i150 = idx["150kft"]
    base = [MomentDerivatives(a, cm_alphadot, q, -0.1, 0.0) for a, q in ((0, 0), (1, 0), (0, 1))]
    w = [np.array([at(i150, b).omega0, at(i150, b).omega1]) for b in base]
    cm_alpha, cm_q = np.linalg.solve(np.column_stack([w[1] - w[0], w[2] - w[0]]),
                                     np.array(OMEGA_150) - w[0])
    rows, rhs = [], []
    for key, i in idx.items():
        c = at(i, MomentDerivatives(cm_alpha, cm_alphadot, cm_q, -1.0, 0.0))
        mu_needed = ((LAMBDA_FL[key] ** 2 - c.omega0) * ALPHA_I + c.f) / DELTA_E_MAX
        unit = c.mu  # mu for C_mdeltae = -1
        rows.append([-unit, -unit * trajectory.alpha0[i]])
        rhs.append(mu_needed)
    cm_de_0, cm_de_1 = np.linalg.solve(np.array(rows), np.array(rhs))
    return MomentDerivatives(float(cm_alpha), cm_alphadot, float(cm_q), float(cm_de_0), float(cm_de_1))


def predict(h0: float, v0: float, gamma0: float, xi_span: float, samples: int = 2000) -> Trajectory:
    """The nominal glide flown from (h0 m, v0 m/s, gamma0 rad) over at least xi_span lengths:
    the a priori data of the LQR laws (extraction A-22). About `samples` RK4 steps."""
    t_max = 1.5 * xi_span * GENERIC.L / v0 + 5.0
    dt = min(0.5, max(0.002, t_max / samples))
    return fly(h0, v0, gamma0, dt=dt, h_stop=0.0, t_max=t_max)


def coefficient_model(trajectory: Trajectory, **model):
    """Callable xi_local -> (omega0, omega1, omega0', omega1') interpolated along `trajectory`,
    xi_local measured from its first sample (the LQR coefficient input)."""
    c = trajectory.coefficients(**model)
    xi = trajectory.xi - trajectory.xi[0]
    tables = [c["omega0"], c["omega1"], np.gradient(c["omega0"], xi), np.gradient(c["omega1"], xi)]
    return lambda x: tuple(float(np.interp(x, xi, tab)) for tab in tables)
