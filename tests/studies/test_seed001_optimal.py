"""Seed 001: numerically optimal maximum-final-speed plane change (our own indirect shooting in
heading), the reference of Calise & Melamed, NASA CR-194523, Sec. 3.8.2.

Expected values: extraction = `shared/research/seed-001-nasa-mae.md`; [R] the report, [V] the
extraction author's independent prototype (Hermite-Simpson collocation with IPOPT, evidence, not
gospel). Angles in the report are in degrees; the code works in rad.
"""

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.interpolate import CubicSpline

from aotv_cosim.guidance import mae
from aotv_cosim.studies.plane_change_plots import optimal_in_mae_units
from aotv_cosim.guidance.plane_change_optimal import (
    PlaneChangeProblem, heading_rates, solve_optimal,
)
from aotv_cosim.physics import mrrv, orbit, point_mass

D = math.radians
PROBLEM = PlaneChangeProblem()


@pytest.fixture(scope="module")
def optimum():
    return solve_optimal(n_points=2001)


def test_optimal_final_speed(optimum):
    """Extraction A24 / 9.3 [V]: optimal V_f = 6734.6 m/s (+-2 m/s) with the extraction's constants
    (N = 300 and 600 collocation, DOP853 replay 6734.64). We get 6734.644 m/s.
    [R] Sec. 3.8.2 states 6751 m/s: NOT reproducible with the stated constants (16.4 m/s lower
    here and in [V]); the extraction keeps it only as a documented value within 20 m/s. The cause
    is unknown (vehicle data of Ref. 24, a model difference, or reporting); E* = 2.4 instead of
    2.362 would give 6751.6 m/s (see test_prototype_sensitivities)."""
    assert optimum.converged and optimum.residual < 1e-10
    assert optimum.v_f == pytest.approx(6734.6, abs=2.0)
    assert abs(optimum.v_f - 6751.0) < 20.0


def test_optimum_meets_boundary_conditions(optimum):
    """Sec. 3.7.2 with A1: 60 km / 7851 m/s / -1.35 deg at entry, 60 km / +1.0 deg at exit after
    20 deg of heading; transversality p_v(psi_f) = 1 (J = V_f)."""
    np.testing.assert_allclose([optimum.z[0], optimum.v[0], optimum.gamma[0]], [60.0e3, 7851.0, D(-1.35)],
                               rtol=1e-12)
    assert optimum.z[-1] == pytest.approx(60.0e3, abs=1e-3)
    assert optimum.gamma[-1] == pytest.approx(D(1.0), abs=1e-10)
    assert optimum.psi[-1] == pytest.approx(D(20.0), rel=1e-15)
    assert optimum.p_v[-1] == pytest.approx(1.0, rel=1e-15)


def test_optimal_trajectory_matches_prototype(optimum):
    """[V] 9.3: t_f = 223.05 s, z_min = 44.52 km at psi = 10.44 deg, lambda in [0.969, 1.057],
    mu in [70.7, 87.6] deg (neither bound of lambda >= 0, mu in [0, 180] deg active)."""
    assert optimum.t_f == pytest.approx(223.05, abs=0.01)
    i_min = int(np.argmin(optimum.z))
    assert optimum.z[i_min] == pytest.approx(44.52e3, abs=10.0)
    assert math.degrees(optimum.psi[i_min]) == pytest.approx(10.44, abs=0.06)
    assert [optimum.lam.min(), optimum.lam.max()] == pytest.approx([0.969, 1.057], abs=6e-4)
    bank = np.degrees(optimum.bank)
    assert [bank.min(), bank.max()] == pytest.approx([70.7, 87.6], abs=0.06)


def test_hamiltonian_is_constant(optimum):
    """The heading-domain Hamiltonian does not depend on psi explicitly, so p_psi = -H = dV_f/dpsi
    is constant along the optimum; a check of the complex-step costate equations."""
    assert np.ptp(optimum.p_psi) < 1e-9 * optimum.p_psi[0]


def test_entry_costates_and_mae_costates(optimum):
    """[V] 9.3/9.5: optimal costates at entry in the MAE normalization (J = u_f, g_s r_s from
    z_min) are P_u = 0.779, P_gamma = 0.027, P_psi = 0.634. The zeroth-order MAE composite gives
    (0.755, -0.0005, 0.624): P_u and P_psi within 2-3 %, P_gamma is where the zeroth order is
    weak ([R] Sec. 4.3, Fig. 4.2). The conversion is the one of the Figs. 3.13-3.14 plots, with the
    transversality P_u(exit) = 1 (3.116)."""
    gs_rs = PROBLEM.mu_earth / (PROBLEM.r_earth + optimum.z.min())
    p_psi = optimum.p_psi[0] * 2.0 * optimum.v_f / gs_rs
    p_us, p_gammas, _ = optimal_in_mae_units(optimum)
    p_u, p_gamma = p_us[0], p_gammas[0]
    assert [p_u, p_gamma, p_psi] == pytest.approx([0.779, 0.027, 0.634], abs=6e-4)
    assert p_us[-1] == pytest.approx(1.0, rel=1e-12)

    state = mae.State(PROBLEM.r_earth + PROBLEM.z_i, PROBLEM.v_i, PROBLEM.gamma_i, 0.0)
    k = mae.solve(state, mae.Targets(PROBLEM.z_f, PROBLEM.gamma_f, PROBLEM.dpsi)).constants
    _, _, mae_p_u, mae_p_gamma = k.composite(k.left, (state.r - k.r_s) / k.r_s, 0.0)
    assert mae_p_u == pytest.approx(p_u, rel=0.04)
    assert k.inner.p_psi == pytest.approx(p_psi, rel=0.02)
    assert abs(mae_p_gamma) < 0.2 * p_gamma


def test_heading_rates_match_point_mass():
    """heading_rates is (3.1), (3.4)-(3.6) (reduced, phi = 0) of point_mass divided by dpsi/dt."""
    rng = np.random.default_rng(1)
    for _ in range(5):
        z, v, gamma = rng.uniform(40e3, 70e3), rng.uniform(6500, 8000), rng.uniform(-0.04, 0.04)
        lam, bank = rng.uniform(0.5, 1.5), rng.uniform(0.5, 2.5)
        cl, cd = mrrv.coefficients_per_mass(lam)
        dx = point_mass.derivatives([PROBLEM.r_earth + z, 0.0, 0.0, v, gamma, 0.0], mrrv.density(z), 0.0,
                                    cl, cd, bank, point_mass.GRAVITY_INVERSE_SQUARE, 9.81, PROBLEM.mu_earth)
        got = heading_rates(z, v, gamma, lam * math.sin(bank), lam * math.cos(bank), PROBLEM)
        want = (dx[0] / dx[5], dx[3] / dx[5], dx[4] / dx[5], 1.0 / dx[5])
        np.testing.assert_allclose(got, want, rtol=1e-12)


def _replay(optimum, reduced):
    """Fly the optimal lambda(t), mu(t) (cubic splines in time) with point_mass in the time domain.

    reduced drops the -V^2 cos(gamma) cos(psi) tan(phi)/r term of (3.6) (extraction 2.7) while
    theta and phi are still integrated.
    """
    lam = CubicSpline(optimum.t, optimum.lam)
    bank = CubicSpline(optimum.t, optimum.bank)

    def rhs(t, x):
        cl, cd = mrrv.coefficients_per_mass(float(lam(t)))
        args = (mrrv.density(x[0] - PROBLEM.r_earth), 0.0, cl, cd, float(bank(t)),
                point_mass.GRAVITY_INVERSE_SQUARE, 9.81, PROBLEM.mu_earth)
        dx = list(point_mass.derivatives(x, *args))
        if reduced:
            dx[5] = point_mass.derivatives([x[0], x[1], 0.0, x[3], x[4], x[5]], *args)[5]
        return dx

    x0 = [PROBLEM.r_earth + PROBLEM.z_i, 0.0, 0.0, PROBLEM.v_i, PROBLEM.gamma_i, 0.0]
    return solve_ivp(rhs, (0.0, optimum.t_f), x0, method="DOP853", rtol=1e-10, atol=1e-9).y[:, -1]


def test_time_domain_replay(optimum):
    """[V] 2.7: replaying the optimal control, the reduced model gives psi_f = 20.000 deg,
    phi_f = 2.46 deg, theta_f = 14.15 deg, inclination 20.145 deg, V_f = 6734.64 m/s; the full
    3-D model psi_f = 19.826 deg and inclination 19.971 deg (A26: ~0.17 deg of coupling)."""
    r, theta, phi, v, gamma, psi = _replay(optimum, reduced=True)
    assert v == pytest.approx(optimum.v_f, abs=0.05)
    assert r - PROBLEM.r_earth == pytest.approx(60.0e3, abs=50.0)
    assert math.degrees(gamma) == pytest.approx(1.0, abs=0.005)
    assert math.degrees(psi) == pytest.approx(20.0, abs=0.002)
    assert [math.degrees(phi), math.degrees(theta)] == pytest.approx([2.46, 14.15], abs=0.006)
    assert math.degrees(orbit.inclination(phi, psi)) == pytest.approx(20.145, abs=6e-4)
    r, theta, phi, v, gamma, psi = _replay(optimum, reduced=False)
    assert math.degrees(psi) == pytest.approx(19.826, abs=6e-4)
    assert math.degrees(orbit.inclination(phi, psi)) == pytest.approx(19.971, abs=6e-4)


@pytest.mark.slow
@pytest.mark.parametrize("change, v_f", [
    ({"e_star": 2.4}, 6751.64),
    ({"gamma_f": D(0.5)}, 6738.43),
    ({"gamma_i": D(-1.0)}, 6734.80),
    ({"gamma_i": D(-1.5)}, 6734.21),
    ({"z_ref": 30.0e3, "rho_ref": 1.8410e-2}, 6736.90),
    ({"z_ref": 45.0e3, "rho_ref": 1.9663e-3}, 6732.85),
    ({"r_earth": 6371.0e3}, 6734.38),
    ({"mu_earth": 9.80665 * 6378137.0 ** 2}, 6734.47),
])
def test_prototype_sensitivities(change, v_f):
    """[V] 9.3 sensitivities of the optimal V_f (m/s, printed to 0.01), all converging from the
    pure-turn guess. E* = 2.4 reaches the report's 6751 m/s; the density anchor (A2), R_E and mu_E
    (A3) move V_f by at most ~2.3 m/s."""
    sol = solve_optimal(replace(PROBLEM, **change))
    assert sol.converged
    assert sol.v_f == pytest.approx(v_f, abs=0.011)
