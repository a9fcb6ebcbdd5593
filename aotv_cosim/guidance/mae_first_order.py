"""First-order HJB correction of the MAE costates (experimental), Calise & Melamed Sec. 4.

Extraction 4.8 with A20-A22. The first-order composite return function at the current state x_i is
(4.58) with R_1^o = 0 (4.60):

    P_1^c(x_i) = P_0^c(x_i) + eps Q(x_i),   P_0^c = u_f^c (the composite prediction of J = u_f),
    Q = -int_{psi_i}^{psi_s} (gamma/(sigma w)) [R_1^i - R^L_inf] dpsi
        -int_{psi_s}^{psi_f} (gamma/(sigma w)) [R_1^i - R^R_inf] dpsi            (4.62)-(4.65)
    R_1^i = 2 P_0u^i - P_0gamma^i (1 - 1/u_0^i) cot gamma_0^i   (A20),  R^S_inf = 2 a1^S - a2^S (4.61)

along the zeroth-order inner solution (3.61)-(3.64), (3.83); in the exit phase (x_i past the
lowest point, the t_i >= 0 case (4.32)) only the right integral from psi_i remains. As the
extraction recommends (A22), the costates are the finite-difference gradient of the whole map
x_i -> P_1^c (a warm MAE re-solve plus the quadrature per perturbed state) with respect to
(u_i, gamma_i, psi_i) at fixed radius; J is kept in the u units of the unperturbed solve.
The report found this correction to overcorrect early in the entry (Fig. 4.2); it is off by default.
"""

import math

import numpy as np

from aotv_cosim.guidance import mae, mae_solution

QUAD_NODES = 64
"""Gauss-Legendre nodes per heading interval of the quadrature."""
STEPS = (0.01, 1e-6, 1e-6)
"""Central-difference steps in V (m/s), gamma and psi (rad)."""


def _gamma_cot_gamma(gamma):
    """gamma cot gamma, equal to 1 at gamma = 0."""
    return np.cos(gamma) / np.sinc(gamma / math.pi)


def _integral(k: mae_solution.MaeConstants, side: mae_solution.OuterSide, psi_a: float, psi_b: float) -> float:
    """int_{psi_a}^{psi_b} (gamma/(sigma w)) [R_1^i - R_inf] dpsi on one side (Gauss-Legendre)."""
    if psi_b <= psi_a:
        return 0.0
    x, wts = np.polynomial.legendre.leggauss(QUAD_NODES)
    psi = 0.5 * (psi_b - psi_a) * x + 0.5 * (psi_b + psi_a)
    inner = k.inner
    gamma, w, u = inner.gamma(psi), inner.w(psi), k.inner_u(psi)
    p_u = -k.e_star * inner.p_v / u
    r_inf = 2.0 * side.a1 - side.a2
    integrand = ((2.0 * p_u - r_inf) * gamma
                 - inner.p_gamma(psi) * (1.0 - 1.0 / u) * _gamma_cot_gamma(gamma)) / (inner.sigma * w)
    return float(0.5 * (psi_b - psi_a) * np.dot(wts, integrand))


def return_correction(k: mae_solution.MaeConstants, psi_i: float, psi_f: float) -> float:
    """Q(x_i) of the module docstring (dimensionless, u units); psi_i, psi_f in rad."""
    if k.mode == mae.ENTRY and psi_i < k.psi_s:
        assert k.left is not None  # the entry phase has its left outer solution
        return -_integral(k, k.left, psi_i, k.psi_s) - _integral(k, k.right, k.psi_s, psi_f)
    return -_integral(k, k.right, psi_i, psi_f)


def return_function(k: mae_solution.MaeConstants, state: mae.State, targets: mae.Targets, r_earth: float,
                    gs_rs_ref: float, order: int = 1) -> float:
    """P_1^c = u_f^c + eps Q at `state` (order 1) or P_0^c = u_f^c (order 0), with u_f in units
    of gs_rs_ref (m^2/s^2)."""
    v_f = k.exit_speed(r_earth + targets.z_f, targets.psi_f)
    correction = k.eps * return_correction(k, state.psi, targets.psi_f) if order == 1 else 0.0
    return v_f * v_f / gs_rs_ref + correction


def first_order_costates(base: mae.MaeSolution, state: mae.State, targets: mae.Targets,
                         model: mae.MaeModel = mae.MaeModel(), order: int = 1):
    """(P_u, P_gamma, P_psi) = grad P_1^c by central differences, or None if a solve fails.

    order 0 differentiates P_0^c = u_f^c instead (the HJB-consistency check of extraction 9.5).
    base: the converged zeroth-order solution at `state` (warm start of the perturbed solves).
    dJ/du = dJ/dV g_s r_s/(2 V) at fixed r (3.12).
    """
    k = base.constants
    grads = []
    for i, step in enumerate(STEPS):
        values = []
        for sign in (1.0, -1.0):
            x = [state.v, state.gamma, state.psi]
            x[i] += sign * step
            moved = mae.State(state.r, *x)
            sol = mae.solve(moved, targets, base, model)
            if not sol.converged:
                return None
            values.append(return_function(sol.constants, moved, targets, model.r_earth, k.gs_rs,
                                           order))
        grads.append((values[0] - values[1]) / (2.0 * step))
    return grads[0] * k.gs_rs / (2.0 * state.v), grads[1], grads[2]
