"""Zeroth-order matched-asymptotic-expansion (MAE) guidance for the aeroassisted plane change.

Calise & Melamed, NASA CR-194523 (1993), Sec. 3 and App. B, as read in the seed-001 extraction
(Secs. 4.1-4.7, ambiguities A1-A19). Normalized variables (eqs. 3.11-3.15, 3.41-3.46):

    h = (r - r_s)/r_s,  u = V^2/(g_s r_s),  eps = H_s/r_s,  w = K_w rho(r),  v = -E* ln(V^2 [m^2/s^2])

r_s is the minimum radius of the solution (computed, A4), g_s r_s = mu_E/r_s. Angles are in rad.

The solution forms (outer, inner, composite) are in `aotv_cosim.guidance.mae_solution`; this
module solves for their constants:

* Outer (Keplerian) solution, eqs. (3.31)-(3.33), (3.38)-(3.40): one constant set per side,
  left (entry, gamma < 0) and right (exit, gamma > 0), built from the common parts (3.68)-(3.98).
* Inner (Hull, Loh's term = 0) solution with heading psi as independent variable, (3.61)-(3.67),
  its constants from the common parts by (B2)-(B7), sigma by (B5) or its Delta-w generalization.
* Composite x_c = x_outer(h) + x_inner(psi) - x_common, eqs. (3.99)-(3.110).
* Nested Newton (Sec. 3.7.1, App. B): an inner Newton on (psi_L, psi_R) meets the heading
  conditions through w_inner(psi_i) = w_i, w_inner(psi_f) = w_f; an outer 4x4 Newton on
  (gamma_L, v_L, gamma_R, P_vR) meets the four conditions (3.124).
* Exit phase (Sec. 3.8.1, App. B.2, extraction 4.7): the left outer solution is dropped, the
  left inner point is the current point (psi_L = psi, w_L = w), r_s stays frozen at its last
  entry value. A failed re-solve keeps the last converged constants (extraction A19).
"""

import math
import time
from dataclasses import dataclass

import numpy as np

from aotv_cosim.guidance.mae_solution import (ENTRY, EXIT, MaeConstants, OuterSide, inner_from_common,
                                              signed_arccos)
from aotv_cosim.guidance.newton import damped_newton
from aotv_cosim.physics import constants, mrrv


DV_DPSI_GUESS = 2.0
"""App. B.1 starting guess dv_inner/dpsi = 2 (verified from the report's Fig. 3.5)."""
H_GUESS = 0.0017
"""Starting guess of h at the entry point, used to place r_s before the first solve (extraction 4.6)."""
OUTER_TOL = 1e-12
"""Convergence threshold on the max-norm of the residuals (3.124) (u, gamma in rad, P_u)."""
INNER_TOL = 1e-16
"""Convergence threshold on |w_inner - w| at the heading conditions (w is about 1e-3)."""
MAX_ITER = 40
"""Iteration limit of each Newton solve."""


@dataclass(frozen=True)
class MaeModel:
    """Vehicle, atmosphere and planet data of the MAE guidance, SI units (Sec. 3.7.1, extraction A2-A3)."""

    e_star: float = mrrv.E_STAR
    cl_star: float = mrrv.CL_STAR
    s_ref: float = mrrv.S_REF
    mass: float = mrrv.MASS
    scale_height: float = mrrv.H_SCALE
    rho_ref: float = mrrv.RHO_REF
    z_ref: float = mrrv.Z_REF
    r_earth: float = mrrv.R_EARTH
    mu_earth: float = constants.MU_EARTH

    @property
    def k_w(self) -> float:
        """K_w = C_L* S H_s/(2m), m^3/kg, so that w = B e^{-h/eps} = K_w rho(r) (eqs. 3.13, 3.43)."""
        return self.cl_star * self.s_ref * self.scale_height / (2.0 * self.mass)

    def w_at_radius(self, r: float) -> float:
        """Inner altitude variable w = K_w rho(r) (eq. 3.43), dimensionless; r in m."""
        return self.k_w * mrrv.density(r - self.r_earth, self.rho_ref, self.z_ref, self.scale_height)

    def radius_at_w(self, w: float) -> float:
        """Radius (m) where K_w rho = w; with w = w_s this is r_s of eq. (3.115)."""
        return self.r_earth + mrrv.altitude_at_density(w / self.k_w, self.rho_ref, self.z_ref,
                                                       self.scale_height)


@dataclass(frozen=True)
class State:
    """Measured state: radius r (m), speed v (m/s), flight-path angle gamma and heading psi (rad)."""

    r: float
    v: float
    gamma: float
    psi: float


@dataclass(frozen=True)
class Targets:
    """Exit conditions: altitude z_f (m), flight-path angle gamma_f and heading psi_f (rad) (3.121-3.123)."""

    z_f: float
    gamma_f: float
    psi_f: float


@dataclass(frozen=True)
class MaeSolution:
    """Result of `solve`: constants to fly with, and how the solve went.

    constants are the last converged ones when this solve failed (A19). iterations counts outer
    Newton steps, residual is the final max-norm of (3.124), solve_time is wall-clock seconds,
    mode is the phase this solve was attempted in (ENTRY or EXIT).
    """

    constants: MaeConstants
    converged: bool
    iterations: int
    residual: float
    solve_time: float
    mode: str


def _newton(fun, x0, steps, tol):
    """Damped Newton (shared solver) with this module's iteration limit."""
    return damped_newton(fun, x0, steps, tol, MAX_ITER)


@dataclass
class _Problem:
    """Data of one solve: normalized boundary data and the frozen/warm-start quantities."""

    model: MaeModel
    state: State
    targets: Targets
    mode: str
    w_i: float
    w_f: float
    psi_guess: np.ndarray
    r_s_frozen: float = math.nan

    @property
    def r_f(self) -> float:
        """Exit radius, m."""
        return self.model.r_earth + self.targets.z_f


def _solve_headings(prob: _Problem, gamma_l: float, gamma_r: float, v_l: float, p_v: float):
    """Inner Newton (Sec. 3.7.1): common-part headings so that w_0^i(psi_i) = w_i, w_0^i(psi_f) = w_f.

    Entry: unknowns (psi_L, psi_R) with w_L = 0. Exit: psi_L = psi_i, w_L = w_i, unknown psi_R.
    Returns (Inner, psi_R), or None if the inner Newton fails. Warm-starts from, and updates,
    prob.psi_guess = (psi_L, psi_R).
    """
    psi_i, psi_f = prob.state.psi, prob.targets.psi_f
    steps: tuple[float, ...]  # one finite-difference step per unknown
    if prob.mode == ENTRY:
        def build(x):
            return inner_from_common(x[0], x[1], gamma_l, gamma_r, 0.0, v_l, p_v)

        def fun(x):
            inner = build(x)
            return np.array([inner.w(psi_i) - prob.w_i, inner.w(psi_f) - prob.w_f])
        x0, steps = prob.psi_guess, (1e-7, 1e-7)
    else:
        def build(x):
            return inner_from_common(psi_i, x[0], gamma_l, gamma_r, prob.w_i, v_l, p_v)

        def fun(x):
            return np.array([build(x).w(psi_f) - prob.w_f])
        x0, steps = prob.psi_guess[1:], (1e-7,)
    x, ok, _, _ = _newton(fun, x0, steps, INNER_TOL)
    if not ok:
        return None
    prob.psi_guess = np.array([psi_i, x[0]]) if prob.mode == EXIT else x
    return build(x), float(prob.psi_guess[1])


def _constants(prob: _Problem, x: np.ndarray):
    """MaeConstants for outer unknowns x = (gamma_L, v_L, gamma_R, P_vR), or None (Sec. 3.7.1).

    Reference radius from (3.112)-(3.115) in the entry phase, frozen in the exit phase; outer
    constants from the common parts (3.68)-(3.98) (extraction 4.3).
    """
    gamma_l, v_l, gamma_r, p_v = x
    headings = _solve_headings(prob, gamma_l, gamma_r, v_l, p_v)
    if headings is None or not 0.0 < headings[0].sigma <= 1.0:
        return None
    inner, psi_r = headings
    m = prob.model
    if prob.mode == ENTRY:
        psi_s = inner.lowest_heading()
        w_s = inner.w(psi_s)
        if not (inner.psi_l < psi_s < psi_r and w_s > 0.0):
            return None
        r_s = m.radius_at_w(w_s)
    else:
        psi_s, r_s = math.nan, prob.r_s_frozen
        w_s = m.w_at_radius(r_s)
    gs_rs = m.mu_earth / r_s
    u_l = math.exp(-v_l / m.e_star) / gs_rs
    u_r = math.exp(-inner.v(psi_r) / m.e_star) / gs_rs
    left = None
    if prob.mode == ENTRY:
        left = OuterSide.from_common(-1.0, u_l, gamma_l, -m.e_star * p_v / u_l,
                                     inner.p_gamma(inner.psi_l))
    right = OuterSide.from_common(1.0, u_r, gamma_r, -m.e_star * p_v / u_r, inner.p_gamma(psi_r))
    return MaeConstants(prob.mode, inner, left, right, psi_r, psi_s, r_s,
                        m.scale_height / r_s, gs_rs, w_s, m.e_star)


def boundary_residuals(k: MaeConstants, state: State, targets: Targets, r_earth: float) -> np.ndarray:
    """Residuals of (3.124): u_c(h_i) - u_i, gamma_c(h_i) - gamma_i, P_uc(h_f) - 1, gamma_c(h_f) - gamma_f.

    The heading conditions (3.120)-(3.121) hold by construction of the inner solution. The
    initial point uses the left outer solution in the entry phase, the right one in the exit phase.
    """
    h_i = (state.r - k.r_s) / k.r_s
    h_f = (r_earth + targets.z_f - k.r_s) / k.r_s
    u_i = state.v ** 2 / k.gs_rs
    u_c, g_c, _, _ = k.composite(k.side(True), h_i, state.psi)
    _, g_f, p_uf, _ = k.composite(k.right, h_f, targets.psi_f)
    return np.array([u_c - u_i, g_c - state.gamma, p_uf - 1.0, g_f - targets.gamma_f])


def _residuals(prob: _Problem, x: np.ndarray) -> np.ndarray:
    """(3.124) as a function of the outer unknowns; nan where the constants do not exist."""
    k = _constants(prob, x)
    if k is None:
        return np.full(4, math.nan)
    return boundary_residuals(k, prob.state, prob.targets, prob.model.r_earth)


def _kepler_to_h0(u: float, gamma: float, h: float, sign: float):
    """(u, gamma) at h = 0 on the Kepler arc through (u, gamma) at h, (3.31)-(3.32) (extraction A11)."""
    c1 = 0.5 * u - 1.0 / (1.0 + h)
    c2 = (1.0 + h) * math.sqrt(u) * math.cos(gamma)
    u0 = 2.0 * (c1 + 1.0)
    return u0, float(signed_arccos(c2 / math.sqrt(u0), sign))


def _cold_start(prob: _Problem) -> np.ndarray:
    """App. B.1 starting guess with the Kepler back-propagation of extraction A11.

    gamma_L, u_L and gamma_R are the entry and exit conditions carried along Kepler arcs to
    h = 0, v_R = v_L + 2 (psi_f - psi_i), P_vR = -u_R/E* (from P_u(h_f) ~ 1 and 3.83). r_s
    starts at r_i/(1 + H_GUESS) and is updated twice from the inner solution (3.112)-(3.115).
    """
    m, st, tg = prob.model, prob.state, prob.targets
    r_s = st.r / (1.0 + H_GUESS)
    for _ in range(3):
        gs_rs = m.mu_earth / r_s
        h_i = (st.r - r_s) / r_s
        h_f = (prob.r_f - r_s) / r_s
        u_l, gamma_l = _kepler_to_h0(st.v ** 2 / gs_rs, st.gamma, h_i, -1.0)
        v_l = -m.e_star * math.log(u_l * gs_rs)
        u_r = math.exp(-(v_l + DV_DPSI_GUESS * (tg.psi_f - st.psi)) / m.e_star) / gs_rs
        u_f = u_r - 2.0 + 2.0 / (1.0 + h_f)
        _, gamma_r = _kepler_to_h0(u_f, tg.gamma_f, h_f, 1.0)
        x = np.array([gamma_l, v_l, gamma_r, -u_r / m.e_star])
        k = _constants(prob, x)
        if k is None:
            break
        r_s = k.r_s
    return x


def _mode(state: State, previous: "MaeSolution | None") -> str:
    """Exit phase once the measured gamma >= 0 or the previous solve was in the exit phase (A18)."""
    if previous is not None and previous.constants.mode == EXIT:
        return EXIT
    return EXIT if state.gamma >= 0.0 else ENTRY


def solve(state: State, targets: Targets, previous: "MaeSolution | None" = None,
          model: MaeModel = MaeModel()) -> MaeSolution:
    """Zeroth-order MAE solve from a measured state (Secs. 3.6-3.8.1, App. B).

    state: current r (m), V (m/s), gamma, psi (rad); targets: exit altitude (m), gamma_f, psi_f
    (rad); previous: the last MaeSolution (warm start, frozen r_s in the exit phase, and the
    constants kept on failure). The first call must be in the entry phase (gamma < 0).
    Raises RuntimeError if the very first solve fails (there are no constants to keep).
    """
    t0 = time.perf_counter()
    mode = _mode(state, previous)
    if mode == EXIT and previous is None:
        raise ValueError("the exit phase needs a previous entry-phase solution (frozen r_s)")
    prob = _Problem(model, state, targets, mode, model.w_at_radius(state.r),
                    model.w_at_radius(model.r_earth + targets.z_f),
                    np.array([state.psi, targets.psi_f]))
    if previous is None:
        x0 = _cold_start(prob)
    else:
        k_prev = previous.constants
        prob.psi_guess = np.array([k_prev.psi_l, k_prev.psi_r])
        prob.r_s_frozen = k_prev.r_s
        x0 = k_prev.unknowns(state.psi)
    x, ok, iterations, residual = _newton(lambda x: _residuals(prob, x), x0,
                                          (1e-8, 1e-7, 1e-8, 1e-8), OUTER_TOL)
    k = _constants(prob, x) if ok else None
    if k is None:
        if previous is None:
            raise RuntimeError(f"MAE solve failed (residual {residual:.3g}) with nothing to keep")
        return MaeSolution(previous.constants, False, iterations, residual,
                           time.perf_counter() - t0, mode)
    return MaeSolution(k, True, iterations, residual, time.perf_counter() - t0, mode)
