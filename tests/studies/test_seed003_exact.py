"""Seed 003 tier A: exact, trajectory-independent checks (extraction Sec. 6.5), and the
reconstruction's own consistency (calibration, scenario start states)."""

import json
import math

import numpy as np
import pytest

from aotv_cosim.guidance import shuttle_laws as laws
from aotv_cosim.guidance import shuttle_lqr as lqr
from aotv_cosim.physics import shuttle_pitch as sp
from aotv_cosim.physics import shuttle_trajectory as st

from tests.helpers import SCENARIOS

# Extraction Sec. 6.4 inputs (fitted to the printed Sec. 4.3.4 coefficients)
OMEGA0, OMEGA1, R_EFF, XI_F = 5.596e-5, 1.7698e-3, 1.0 / 2.2334e-7, 446.76
PRINTED_C = {  # Sec. 4.3.4 / extraction 6.3: (i, j, k) zero-based, k = 0 (C_ij1) or 2 (C_ij3)
    (0, 0, 0): 89.752 - 135.89j, (0, 1, 0): -0.9088 - 3.4323j,
    (0, 0, 2): (2.1339 - 3.1897j) * 1e-4, (0, 1, 2): (-8.2874 + 1.1559j) * 1e-6,
    (1, 0, 0): (6.9305 - 1.4173j) * 1e3, (1, 1, 0): 77.507 - 133.33j,
    (1, 0, 2): (5.8 + 17.6j) * 1e-3, (1, 1, 2): (2.0294 - 3.5041j) * 1e-4,
}
CONSTANT = lambda xi: (OMEGA0, OMEGA1, 0.0, 0.0)  # noqa: E731
X0 = (math.radians(5.0), 0.0)


def test_generic_vehicle_constants():
    """Extraction Sec. 3.3 derived constants."""
    g = sp.GENERIC
    assert g.beta == pytest.approx(0.696056, rel=1e-6)
    assert g.sigma == pytest.approx(3.045597, rel=1e-6)
    assert g.nu == pytest.approx(-0.988028, rel=1e-6)
    assert g.delta(sp.PLANET.density(150000 * sp.FT)) == pytest.approx(3.778e-4, rel=2e-3)


def test_sixteen_printed_characteristic_coefficients():
    """All 16 printed C_ijk (8 printed, 8 conjugates) from the Sec. 6.4 inputs within 0.5%."""
    c = lqr.characteristic_coefficients(OMEGA0, OMEGA1, 0.0, 0.0, R_EFF, XI_F)
    for (i, j, k), value in PRINTED_C.items():
        assert abs(c[i, j, k] - value) / abs(value) < 5e-3
        assert abs(c[i, j, k + 1] - np.conj(value)) / abs(value) < 5e-3
    s = lqr.roots(OMEGA0, OMEGA1, 0.0, 0.0, R_EFF)
    assert s[0] == pytest.approx(-0.014519 + 0.016281j, rel=1e-3)
    assert s[3] == -s[0] and s[2] == -np.conj(s[0])


def test_quartic_is_the_hamiltonian_polynomial():
    """(4.85) = characteristic polynomial of [[A, -B R^-1 B^T], [-Q, -A^T]] (extraction 5.2)."""
    r = 6.55e6
    a = lqr.a_matrix(OMEGA0, OMEGA1)
    ham = np.block([[a, -np.array([[0, 0], [0, 1 / r]])], [-np.eye(2), -a.T]])
    assert np.sort_complex(lqr.roots(OMEGA0, OMEGA1, 0, 0, r)) == pytest.approx(
        np.sort_complex(np.linalg.eigvals(ham)), rel=1e-8)


def test_riccati_symmetric_with_zero_terminal_value_and_x_to_zero():
    """K stays symmetric, K(xi_f) = 0 (4.27)-(4.29), X*(xi_f) = 0 (4.6); u(xi0) of extraction 6.4."""
    k = lqr.riccati_backward(CONSTANT, XI_F, 6.55e6)
    for xi in (0.0, 100.0, 300.0):
        assert k(xi)[0, 1] == pytest.approx(k(xi)[1, 0], rel=1e-8)
    assert np.abs(k(XI_F)).max() < 1e-12 * np.abs(k(0.0)).max()
    assert k(0.0) == pytest.approx(np.array([[2.785e-2, -3.880e-4], [-3.880e-4, 1.168e-5]]), rel=2e-3)
    num = lqr.NumericalLqr.solve(CONSTANT, XI_F, 6.55e6, X0)
    assert np.abs(num.x[-1]).max() < 1e-12
    assert num.u[0] == pytest.approx(-2.958e-5, rel=2e-3)


def test_asymptotic_equals_riccati_on_constant_coefficients():
    """The Lambda route (4.46), (4.56) with the corrected Omegas equals the backward Riccati K."""
    r = 6.55e6
    k = lqr.riccati_backward(CONSTANT, XI_F, r)
    asym = lqr.AsymptoticLqr.at_final(CONSTANT, XI_F, r)
    for xi in (0.0, 200.0, 440.0):
        assert asym.gain(xi) == pytest.approx(k(xi), rel=1e-6, abs=1e-12)
    num = lqr.NumericalLqr.solve(CONSTANT, XI_F, r, X0)
    _us, xs = asym.trajectory(X0, num.xi)
    assert np.abs(xs - num.x).max() < 1e-8


def test_feedback_linearization_closed_loop_is_eq_3_10():
    """Unsaturated FL on (1.38) with arbitrary coefficients follows (3.10) to solver tolerance."""
    from scipy.integrate import solve_ivp
    lam, w0, w1, f, mu = 1.92e-2, 5.6e-5, 1.77e-3, -5e-8, 6.25e-5

    def rhs(xi, x):
        de = laws.feedback_linearization(x[0], x[1], w0, w1, f, mu, lam)
        return [x[1], f - mu * de - w1 * x[1] - w0 * x[0]]

    xi = np.linspace(0, 600, 31)
    sol = solve_ivp(rhs, (0, 600), X0, t_eval=xi, rtol=1e-11, atol=1e-14)
    assert sol.y[0] == pytest.approx(laws.fl_response(xi, *X0, lam), abs=1e-9)


def test_adaptive_starts_at_zero_and_lyapunov_decreases_with_constant_parameters():
    """delta_e(xi0) = 0 with P_hat = 0; E' <= 0 (5.33) when P' = 0 (constant coefficients)."""
    lam, gam = laws.ADAPTIVE_GAINS["150kft"]
    w0, w1, f, mu = 5.6e-5, 1.77e-3, -5e-8, 6.25e-5
    true_p = [1 / mu, w1 / mu, w0 / mu, f / mu, 0.0]
    law = laws.AdaptiveLaw(lam, gam)
    x = np.array(X0)
    assert law.command(*x) == 0.0
    energy = [law.lyapunov(*x, true_p)]
    dxi = 0.01
    for _ in range(60000):
        de = law.command(*x)
        law.adapt(dxi, *x)
        x = x + dxi * np.array([x[1], f - mu * de - w1 * x[1] - w0 * x[0]])
        energy.append(law.lyapunov(*x, true_p))
    assert np.all(np.diff(energy) <= 1e-9 * energy[0])
    assert abs(x[0]) < math.radians(0.05)


def test_time_and_xi_forms_agree():
    """advance_pitch (time form, Sec. 2.7) equals (1.38) integrated in xi with V'/V = 0."""
    from scipy.integrate import solve_ivp
    c = sp.Coefficients(5.6e-5, 1.77e-3, -5e-8, 6.25e-5, 3.8e-4, 1.77e-3)
    v = 1800.0
    alpha, alpha_dot = sp.advance_pitch(*X0, 10.0, v, c, 0.01, 1e-3)
    xi_end = v * 10.0 / sp.GENERIC.L
    sol = solve_ivp(lambda xi, x: [x[1], c.f - c.mu * 0.01 - c.omega1 * x[1] - c.omega0 * x[0]],
                    (0, xi_end), X0, rtol=1e-12, atol=1e-15)
    assert alpha == pytest.approx(sol.y[0, -1], abs=1e-10)
    assert alpha_dot * sp.GENERIC.L / v == pytest.approx(sol.y[1, -1], abs=1e-12)


@pytest.fixture(scope="module")
def nominal():
    return st.fly()


def test_moment_derivatives_are_the_calibration(nominal):
    """AERO is what calibrate_moment_derivatives gives on the nominal glide (4 digits)."""
    cal = st.calibrate_moment_derivatives(nominal)
    for name in ("cm_alpha", "cm_q", "cm_de_0", "cm_de_1"):
        assert getattr(sp.AERO, name) == pytest.approx(getattr(cal, name), rel=5e-4)


START_REL_TOLERANCE = 1e-9
"""Accepted relative difference between a scenario's stored start state and the nominal flown
today. The nominal is 2667 fixed RK4 steps of 0.5 s (no step-size control whose choices could
flip), so another machine's libm or numpy changes it only by rounding: a relative perturbation
of 1e-13 of the initial state moves the 150 kft state by at most 5e-12 (gamma; 1.2e-12 h,
3e-12 v), an amplification of 50, so a few ulp (1e-15) per step over 2667 steps stays below
1e-10, ten times inside this tolerance, while any change to the model moves it by far more
(halving the step moves h by 1.1e-3)."""


def test_scenarios_start_on_the_nominal(nominal):
    """The 150 kft scenarios start at the first 150,000 ft crossing (to `START_REL_TOLERANCE`);
    wiring polars = POLAR (stored constants, copied exactly)."""
    i = st.start_indices(nominal)["150kft"]
    for path in SCENARIOS.glob("shuttle_*150kft.json"):
        params = json.loads(path.read_text())["parameters"]
        assert params["vehicle.h0"] == pytest.approx(nominal.h[i], rel=START_REL_TOLERANCE)
        assert params["vehicle.v0"] == pytest.approx(nominal.v[i], rel=START_REL_TOLERANCE)
        assert params["vehicle.gamma0"] == pytest.approx(nominal.gamma[i], rel=START_REL_TOLERANCE)
    for path in (SCENARIOS / "systems").glob("shuttle_*.json"):
        vehicle = json.loads(path.read_text())["components"]["vehicle"]["parameters"]
        for key, value in st.POLAR.items():
            assert vehicle[key] == pytest.approx(value, rel=1e-12)
