"""Numerically optimal maximum-final-speed aeroassisted plane change (seed 001 reference, Sec. 3.8.2).

Problem (Calise & Melamed, NASA CR-194523, Secs. 3.1, 3.7.2; extraction A1): the reduced model
(3.1), (3.4)-(3.6) without the tan(phi) term, MRRV data (3.7)-(3.10), maximize V_f (3.24) from
60 km, 7851 m/s, gamma = -1.35 deg to 60 km climbing at +1.0 deg after a 20 deg heading change.

Method (indirect, like the report's multiple-shooting reference, but our own formulation): the
heading psi is the independent variable. It is monotonic because the lift always turns toward
+psi (sigma = lambda sin mu > 0), so the interval [0, Delta psi] is fixed and there is no free
final time. The controls are the lift components sigma = lambda sin mu, delta = lambda cos mu
(eqs. 3.45-3.46). With the Hamiltonian H = p . dx/dpsi of the states x = (z, v, gamma),

    H = [K0 - K2 (1 + sigma^2 + delta^2) + K1 delta] / sigma,
    delta* = K1/(2 K2),   sigma*^2 = -(K0 - K2 + K1^2/(4 K2))/K2,   H* = -2 K2 sigma*,

the same structure as the inner problem (3.55)-(3.57), (A6). Costates obey dp/dpsi = -dH/dx
(complex-step derivatives of H). The two unknowns of the shooting are the initial controls
(sigma_0, delta_0), from which the initial costates follow (p_v = 1 by homogeneity; p_gamma and
p_z from the control law); a damped Newton meets z(psi_f) = z_f and gamma(psi_f) = gamma_f.
The transversality p_v(psi_f) > 0 scales the costates into gradients of V_f.
"""

import math
from dataclasses import dataclass

import numpy as np

from aotv_cosim.guidance.newton import damped_newton
from aotv_cosim.physics import constants, mrrv

GAMMA_SCALE = 0.02
"""Flight-path-angle scale of the shooting residual, rad."""
Z_ESCAPE = 150.0e3
"""Altitude (m) at which a trial trajectory is declared escaped and the shot rejected."""
TOL = 1e-10
"""Convergence threshold on the scaled terminal residuals (altitude / H_s, gamma / GAMMA_SCALE)."""
MAX_ITER = 50
"""Iteration limit of the shooting Newton."""
COMPLEX_STEP = 1e-20
"""Imaginary step of the complex-step derivatives."""


@dataclass(frozen=True)
class PlaneChangeProblem:
    """Boundary conditions (Sec. 3.7.2, A1) and model data (Sec. 3.7.1, A2-A3), SI units, rad.

    lift_factor is C_L* S/(2 m) in m^2/kg, so that k = lift_factor rho (1/m) and L/m = k v^2 lambda.
    """

    z_i: float = 60.0e3
    v_i: float = 7851.0
    gamma_i: float = math.radians(-1.35)
    z_f: float = 60.0e3
    gamma_f: float = math.radians(1.0)
    dpsi: float = math.radians(20.0)
    e_star: float = mrrv.E_STAR
    lift_factor: float = mrrv.CL_STAR * mrrv.S_REF / (2.0 * mrrv.MASS)
    scale_height: float = mrrv.H_SCALE
    rho_ref: float = mrrv.RHO_REF
    z_ref: float = mrrv.Z_REF
    r_earth: float = mrrv.R_EARTH
    mu_earth: float = constants.MU_EARTH


@dataclass(frozen=True)
class OptimalSolution:
    """Optimal trajectory sampled on a uniform heading grid.

    psi, gamma, bank in rad; z in m; v in m/s; t in s. p_z (s^-1), p_v (-), p_gamma (m/s/rad)
    are the gradients of V_f with respect to the state at fixed heading; p_psi = dV_f/dpsi
    (m/s/rad) = -H. x0 = (sigma_0, delta_0) are the converged shooting unknowns.
    """

    psi: np.ndarray
    z: np.ndarray
    v: np.ndarray
    gamma: np.ndarray
    t: np.ndarray
    lam: np.ndarray
    bank: np.ndarray
    p_z: np.ndarray
    p_v: np.ndarray
    p_gamma: np.ndarray
    p_psi: np.ndarray
    x0: tuple
    converged: bool
    iterations: int
    residual: float

    @property
    def v_f(self) -> float:
        """Final speed, m/s."""
        return float(self.v[-1])

    @property
    def t_f(self) -> float:
        """Flight time, s."""
        return float(self.t[-1])


def lift_per_speed_squared(z, p: PlaneChangeProblem):
    """k = C_L* S rho(z)/(2 m), 1/m, so that L/m = k v^2 lambda (eqs. 3.8-3.9); z in m."""
    return p.lift_factor * p.rho_ref * np.exp(-(z - p.z_ref) / p.scale_height)


def heading_rates(z, v, gamma, sigma, delta, p: PlaneChangeProblem):
    """d(z, v, gamma, t)/dpsi of the reduced model, per rad of heading (arrays broadcast).

    (3.1), (3.4), (3.5) divided by (3.6) without the tan(phi) term, with L/m = k v^2 lambda,
    D/m = k v^2 (1 + lambda^2)/(2 E*) (3.9)-(3.10) and dpsi/dt = k v sigma / cos(gamma):
    dz/dpsi = sin g cos g/(k sigma), dv/dpsi = -v cos g (1 + sigma^2 + delta^2)/(2 E* sigma)
    - g_r sin g cos g/(k v sigma), dgamma/dpsi = [delta - (g_r - v^2/r) cos g/(k v^2)] cos g/sigma,
    dt/dpsi = cos g/(k v sigma). z in m, v in m/s, gamma in rad; g_r = mu/r^2 (3.7).
    """
    r = p.r_earth + z
    k = lift_per_speed_squared(z, p)
    g_r = p.mu_earth / r ** 2
    cg, sg = np.cos(gamma), np.sin(gamma)
    ks = k * sigma
    return (sg * cg / ks,
            -v * cg * (1.0 + sigma ** 2 + delta ** 2) / (2.0 * p.e_star * sigma) - g_r * sg * cg / (ks * v),
            (delta - (g_r - v * v / r) * cg / (k * v * v)) * cg / sigma,
            cg / (ks * v))


def control_terms(z, v, gamma, p_v, p_gamma, p: PlaneChangeProblem):
    """(a, b, K1, K2) with K0 = p_z a + b in H = [K0 - K2 (1 + sigma^2 + delta^2) + K1 delta]/sigma.

    a = sin g cos g/k, b = -p_v g_r sin g cos g/(k v) - p_gamma (g_r - v^2/r) cos^2 g/(k v^2),
    K1 = p_gamma cos g, K2 = p_v v cos g/(2 E*); units follow the costates (see OptimalSolution).
    """
    r = p.r_earth + z
    k = lift_per_speed_squared(z, p)
    g_r = p.mu_earth / r ** 2
    cg, sg = np.cos(gamma), np.sin(gamma)
    a = sg * cg / k
    b = -p_v * g_r * sg * cg / (k * v) - p_gamma * (g_r - v * v / r) * cg * cg / (k * v * v)
    return a, b, p_gamma * cg, p_v * v * cg / (2.0 * p.e_star)


def optimal_controls(z, v, gamma, p_z, p_v, p_gamma, p: PlaneChangeProblem):
    """(sigma, delta) maximizing H: delta = K1/(2 K2), sigma = sqrt(-(K0 - K2 + K1^2/(4 K2))/K2).

    The heading-domain form of H_lambda = H_mu = 0 (3.26)-(3.27); nan where sigma^2 <= 0.
    """
    a, b, k1, k2 = control_terms(z, v, gamma, p_v, p_gamma, p)
    sigma_sq = -(p_z * a + b - k2 + k1 * k1 / (4.0 * k2)) / k2
    return np.sqrt(np.where(sigma_sq > 0.0, sigma_sq, np.nan)), k1 / (2.0 * k2)


def _hamiltonian(z, v, gamma, costates, sigma, delta, p):
    """H = p_z dz/dpsi + p_v dv/dpsi + p_gamma dgamma/dpsi at given controls."""
    rates = heading_rates(z, v, gamma, sigma, delta, p)
    return sum(c * r for c, r in zip(costates, rates[:3]))


def _rhs(_psi, y, p):
    """d(z, v, gamma, p_z, p_v, p_gamma, t)/dpsi with the optimal controls; dp/dpsi = -dH/dx."""
    z, v, gamma, p_z, p_v, p_gamma, _ = y
    costates = (p_z, p_v, p_gamma)
    sigma, delta = optimal_controls(z, v, gamma, p_z, p_v, p_gamma, p)
    dz, dv, dgamma, dt = heading_rates(z, v, gamma, sigma, delta, p)
    h = COMPLEX_STEP
    dp = [-_hamiltonian(*(np.array([z, v, gamma], dtype=complex) + 1j * h * e), costates,  # type: ignore[call-arg]
                        sigma, delta, p).imag / h for e in np.eye(3)]  # (mypy cannot count the 3 of *array)
    return [dz, dv, dgamma, *dp, dt]


def initial_costates(sigma0: float, delta0: float, p: PlaneChangeProblem):
    """(p_z, p_v, p_gamma) at the entry point that make (sigma0, delta0) optimal, with p_v = 1.

    Inverts `optimal_controls`: p_gamma = delta0 v/E*, K0 = K2 (1 - sigma0^2) - K1^2/(4 K2).
    """
    p_gamma = delta0 * p.v_i / p.e_star
    a, b, k1, k2 = control_terms(p.z_i, p.v_i, p.gamma_i, 1.0, p_gamma, p)
    k0 = k2 * (1.0 - sigma0 ** 2) - k1 * k1 / (4.0 * k2)
    return float((k0 - b) / a), 1.0, p_gamma


def _escaped(_psi, y, _p):
    """Event: the trial trajectory leaves the atmosphere (z = Z_ESCAPE)."""
    return y[0] - Z_ESCAPE


_escaped.terminal = True  # type: ignore[attr-defined]  # read by solve_ivp


def shoot(x0, p: PlaneChangeProblem, dense: bool = False):
    """Integrate states, costates and time over [0, Delta psi] from the initial controls x0 (DOP853)."""
    from scipy.integrate import solve_ivp  # here: not every law needs scipy

    y0 = [p.z_i, p.v_i, p.gamma_i, *initial_costates(x0[0], x0[1], p), 0.0]
    return solve_ivp(_rhs, (0.0, p.dpsi), y0, method="DOP853", rtol=1e-11, atol=1e-10,
                     args=(p,), events=_escaped, dense_output=dense)


def terminal_residual(x0, p: PlaneChangeProblem) -> np.ndarray:
    """Scaled exit errors ((z - z_f)/H_s, (gamma - gamma_f)/GAMMA_SCALE); nan for a failed shot."""
    sol = shoot(x0, p)
    yf = sol.y[:, -1]
    if sol.status != 0 or not np.all(np.isfinite(yf)):
        return np.full(2, np.nan)
    return np.array([(yf[0] - p.z_f) / p.scale_height, (yf[2] - p.gamma_f) / GAMMA_SCALE])


def _newton(fun, x0, step=1e-7):
    """Damped Newton (shared solver) with this module's tolerance and iteration limit."""
    return damped_newton(fun, x0, [step] * len(x0), TOL, MAX_ITER, min_alpha=1e-4)


def solve_optimal(problem: PlaneChangeProblem = PlaneChangeProblem(), guess=(1.0, 0.0),
                  n_points: int = 201) -> OptimalSolution:
    """Maximize V_f (eq. 3.24) by indirect shooting in heading.

    guess: initial (sigma_0, delta_0); the default is the pure turn at (L/D)max (lambda = 1,
    mu = 90 deg). The trajectory is returned at n_points uniform headings, SI units, rad.
    """
    x, converged, iterations, residual = _newton(lambda x: terminal_residual(x, problem), guess)
    sol = shoot(x, problem, dense=True)
    psi = np.linspace(0.0, problem.dpsi, n_points)
    z, v, gamma, p_z, p_v, p_gamma, t = sol.sol(psi)
    sigma, delta = optimal_controls(z, v, gamma, p_z, p_v, p_gamma, problem)
    scale = p_v[-1]
    _, _, _, k2 = control_terms(z, v, gamma, p_v, p_gamma, problem)
    return OptimalSolution(psi, z, v, gamma, t, np.hypot(sigma, delta), np.arctan2(sigma, delta),
                           p_z / scale, p_v / scale, p_gamma / scale, 2.0 * k2 * sigma / scale,
                           (float(x[0]), float(x[1])), converged, iterations, residual)
