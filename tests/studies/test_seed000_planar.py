"""Seed 000 planar model (thesis eq. 2.7), costates (3.19)-(3.21), linearizations (5.2), (5.3),
(8.17), and the Keplerian coast after exit (extraction Sec. 7).

Sources: `shared/research/seed-000-aotv-thesis.md` ("extraction") and the thesis text it cites.
"""

import math

import numpy as np
import pytest

from aotv_cosim.physics import planar, point_mass
from aotv_cosim.physics.constants import CD0_000, G0, M_OVER_S_000, MU_EARTH, R_EARTH_000, RHO_S_000
from aotv_cosim.physics.orbit import apsis_altitudes, circularization_delta_v, conic_elements

KM = planar.AotvConstants.km()
SI = planar.AotvConstants.si()

# States around the nominal pass (r km, v km/s, gamma rad) and lift accelerations (km/s^2).
STATES_KM = [
    (np.array([6468.1, 8.2, -0.02]), 0.77e-3),
    (np.array([6457.4, 8.186, 0.0015]), 0.39e-3),
    (np.array([6462.9, 8.16, 0.0111]), -0.5e-3),
]


def test_ballistic_parameter_and_units():
    """K = rho_s C_D0 / (2 m/S) = 2.92e-4 1/m = 0.292 1/km (eq. 2.8; extraction Sec. 3.2 [D],
    Table 8.1 nominal row 0.000292 1/m); km constants are Table 4.1 in km (extraction Sec. 2.2)."""
    assert pytest.approx(2.92e-4, rel=1e-12) == planar.K_BALL_000
    assert KM.k_ball == pytest.approx(0.292, rel=1e-12)
    assert (KM.scale_height, KM.r_earth, KM.g) == pytest.approx((7.045, 6378.1, 9.81e-3), rel=1e-12)
    assert (SI.scale_height, SI.r_earth, SI.g) == pytest.approx((7045.0, 6378.1e3, 9.81), rel=1e-12)


@pytest.mark.parametrize("h, v, gamma, u", [
    (90e3, 8200.0, -0.02, 0.77), (79.3e3, 8186.0, 0.0015, 0.39), (85e3, 8160.0, 0.0111, -0.2),
])
def test_planar_model_matches_point_mass_3d(h, v, gamma, u):
    """Eq. (2.7) equals the 3-D Vinh equations of `point_mass` in the planar configuration
    (sigma = 0, phi = psi = 0, constant g, cl_s_m = 0, cd_s_m = C_D0/(m/S), rho of eq. 2.5),
    in SI and in km-s after unit conversion (extraction Sec. 2.1-2.2)."""
    r = R_EARTH_000 + h
    rho = RHO_S_000 * math.exp(-h / SI.scale_height)
    full = point_mass.derivatives((r, 0.0, 0.0, v, gamma, 0.0), rho, u, 0.0, CD0_000 / M_OVER_S_000,
                                  0.0, point_mass.GRAVITY_CONSTANT, G0, MU_EARTH)
    expected = np.array([full[0], full[3], full[4]])
    np.testing.assert_allclose(planar.dynamics(np.array([r, v, gamma]), u, SI), expected,
                               rtol=1e-12, atol=1e-15)
    in_km = planar.dynamics(planar.km_state((h, v, gamma)), u * 1e-3, KM)
    np.testing.assert_allclose(in_km * np.array([1e3, 1e3, 1.0]), expected, rtol=1e-11, atol=1e-15)
    assert full[2] == 0.0 and full[5] == 0.0  # stays in the plane


def test_model_vectorizes_over_points():
    """(2.7), (3.19) and (3.21) accept (3, n) arrays as solve_bvp passes them."""
    x = np.column_stack([s for s, _u in STATES_KM])
    u = np.array([u for _s, u in STATES_KM])
    lam = np.tile(np.array([[-5.46e-6], [-4.27e-4], [-1.258e-2]]), (1, 3))
    batch = planar.dynamics(x, u, KM)
    for i, (state, ui) in enumerate(STATES_KM):
        np.testing.assert_allclose(batch[:, i], planar.dynamics(state, ui, KM), rtol=1e-14)
    assert planar.augmented_dynamics(np.vstack([x, lam]), KM).shape == (6, 3)


def _hamiltonian(x, lam, u, weight=1.0):
    """H = R u^2 + lambda^T f of eqs. (3.6)/(3.10)."""
    return weight * u * u + lam @ planar.dynamics(x, u, KM)


@pytest.mark.parametrize("index", range(3))
def test_costates_are_minus_dH_dx(index):
    """Eq. (3.19): d(lambda)/dt = -(dH/dx)^T, checked by central differences of H (eq. 3.4;
    extraction Sec. 2.3 [D] re-derived it by hand), and dH/du = 0 at u of eq. (3.20)."""
    x, u = STATES_KM[index]
    lam = np.array([-5.46e-6, -4.27e-4, -1.258e-2])
    steps = np.array([1e-3, 1e-6, 1e-7])
    grad = np.array([(_hamiltonian(x + dx, lam, u) - _hamiltonian(x - dx, lam, u)) / (2 * dx[i])
                     for i, dx in enumerate(np.diag(steps))])
    np.testing.assert_allclose(planar.costate_dynamics(x, lam, u, KM), -grad, rtol=1e-6)
    u_opt = planar.optimal_control(x, lam)
    du = 1e-7
    dh_du = (_hamiltonian(x, lam, u_opt + du) - _hamiltonian(x, lam, u_opt - du)) / (2 * du)
    assert abs(dh_du) < 1e-12


def test_augmented_system_is_state_plus_costates_under_optimal_control():
    """Eq. (3.21) is (2.7) and (3.19) with u = -lambda_gamma/(2 R v) (3.20) substituted."""
    x, _u = STATES_KM[0]
    lam = np.array([-5.46e-6, -4.27e-4, -1.258e-2])
    u = -lam[2] / (2.0 * x[1])
    y = planar.augmented_dynamics(np.concatenate([x, lam]), KM)
    np.testing.assert_allclose(y[:3], planar.dynamics(x, u, KM), rtol=1e-15)
    np.testing.assert_allclose(y[3:], planar.costate_dynamics(x, lam, u, KM), rtol=1e-15)


@pytest.mark.parametrize("index", range(3))
def test_linearization_matches_numerical_jacobian(index):
    """A of eq. (5.2) and B of (5.3) equal the Jacobians of (2.7), except A(3,1), which the
    thesis prints without cos(gamma) (extraction Sec. 2.6 [D])."""
    x, u = STATES_KM[index]
    steps = np.array([1e-4, 1e-7, 1e-8])
    jac = np.column_stack([(planar.dynamics(x + dx, u, KM) - planar.dynamics(x - dx, u, KM))
                           / (2 * dx[i]) for i, dx in enumerate(np.diag(steps))])
    a_mat = planar.jacobian_a(x, u, KM)
    exact = a_mat.copy()
    exact[2, 0] *= math.cos(x[2])
    np.testing.assert_allclose(exact, jac, rtol=1e-5, atol=1e-12)
    du = 1e-8
    b_num = (planar.dynamics(x, u + du, KM) - planar.dynamics(x, u - du, KM)) / (2 * du)
    np.testing.assert_allclose(planar.input_b(x), b_num, rtol=1e-6, atol=1e-12)


def test_adaptive_model_matrix_differs_from_5_2_only_in_drag_row():
    """Eq. (8.17) is (5.2) with A(2,1) = 0 and the drag density taken at r_avg (extraction
    Sec. 4.9 and Sec. 8 item 17a)."""
    x, u = STATES_KM[1]
    r_avg = KM.r_earth + 82.9
    a_m = planar.adaptive_model_matrix(x, u, r_avg, KM)
    a_full = planar.jacobian_a(x, u, KM)
    mask = np.ones((3, 3), bool)
    mask[1, :2] = False
    np.testing.assert_array_equal(a_m[mask], a_full[mask])
    assert a_m[1, 0] == 0.0
    assert a_m[1, 1] == pytest.approx(-2 * KM.k_ball * math.exp(-82.9 / 7.045) * x[1], rel=1e-12)


def test_exit_orbit_apogee_and_circularization():
    """Nominal exit (90 km, 8.15 km/s, 0.0144 rad): a = 7014.07 km, e = 0.07915, apogee 1191.15
    km, perigee 80.8 km, apogee circularization 0.2931 km/s (extraction Sec. 5 and Sec. 7 [D],
    mu = 398600.4418 km^3/s^2)."""
    sma, ecc, _ = conic_elements(R_EARTH_000 + 90e3, 8150.0, 0.0144)
    assert sma == pytest.approx(7014.07e3, abs=10.0)
    assert ecc == pytest.approx(0.07915, abs=5e-6)
    perigee, apogee = apsis_altitudes(90e3, 8150.0, 0.0144)
    assert apogee == pytest.approx(1191.15e3, abs=5.0)
    assert perigee == pytest.approx(80.8e3, abs=50.0)
    assert circularization_delta_v(90e3, 8150.0, 0.0144) == pytest.approx(293.1, abs=0.05)


def test_entry_orbit_apsides():
    """Entry state (90 km, 8.2 km/s, -0.02 rad) implies a = 7116.45 km, e = 0.09326, apogee
    1402.0 km, perigee 74.7 km and a 0.3419 km/s apogee circularization (extraction Sec. 5 [D])."""
    sma, ecc, _ = conic_elements(R_EARTH_000 + 90e3, 8200.0, -0.02)
    assert sma == pytest.approx(7116.45e3, abs=10.0)
    assert ecc == pytest.approx(0.09326, abs=5e-6)
    perigee, apogee = apsis_altitudes(90e3, 8200.0, -0.02)
    assert apogee == pytest.approx(1402.0e3, abs=50.0)
    assert perigee == pytest.approx(74.7e3, abs=50.0)
    assert circularization_delta_v(90e3, 8200.0, -0.02) == pytest.approx(341.9, abs=0.05)


def test_time_linear_variational_matches_dynamics_and_jacobian():
    """The scalar right-hand side used by the shooting solver is (2.7) plus dS/dt = A S + B (1, t)
    with A, B of (5.2)/(5.3), to rounding, in SI and in km-s units."""
    rng = np.random.default_rng(4)
    for c in (planar.AotvConstants.si(), planar.AotvConstants.km()):
        scale = 1.0 if c.r_earth > 1e5 else 1e-3
        for _ in range(5):
            x = np.array([c.r_earth + rng.uniform(75e3, 95e3) * scale, rng.uniform(8.0e3, 8.3e3) * scale,
                          rng.uniform(-0.03, 0.03)])
            sens = rng.normal(size=(3, 2))
            a, b, t = 0.7 * scale, -2.5e-3 * scale, rng.uniform(0.0, 300.0)
            got = planar.time_linear_variational(t, np.concatenate([x, sens.ravel()]), a, b, c)
            u = a + b * t
            expected_s = planar.jacobian_a(x, u, c) @ sens + np.outer(planar.input_b(x), [1.0, t])
            np.testing.assert_allclose(got[:3], planar.dynamics(x, u, c), rtol=1e-13, atol=1e-18)
            np.testing.assert_allclose(got[3:], expected_s.ravel(), rtol=1e-12, atol=1e-15)
