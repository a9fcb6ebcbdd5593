"""Unit tests of the physics used by the issue-2 FMUs (atmosphere, drag, heating, actuator, law)."""

import math

import pytest

from aotv_cosim.guidance.time_linear import approximate_law_coefficients, lambda_r_empirical
from aotv_cosim.physics import aero, point_mass
from aotv_cosim.physics.actuator import advance, saturate
from aotv_cosim.physics.atmosphere import exponential_density


def test_density_at_interface_and_minimum_altitude():
    """Seed-000 extraction Sec. 3.2 [D]: rho(90 km) = 4.959e-6, rho(79.26 km) = 2.278e-5 kg/m^3."""
    assert exponential_density(90e3, 1.752, 0.0, 7045.0) == pytest.approx(4.959e-6, rel=2e-4)
    assert exponential_density(79.26e3, 1.752, 0.0, 7045.0) == pytest.approx(2.278e-5, rel=3e-4)


def test_entry_drag_acceleration():
    """Seed-000 extraction Sec. 3.2 [D]: D/m = 0.0556 m/s^2 at entry (90 km, 8.2 km/s)."""
    rho = exponential_density(90e3, 1.752, 0.0, 7045.0)
    assert aero.parasite_drag_acceleration(rho, 8200.0, 0.1, 300.0) == pytest.approx(0.0556, rel=1e-3)


def test_sutton_graves_and_load_factor():
    """q = k sqrt(rho/Rn) v^3; n = |(L, D)| / g0."""
    assert aero.stagnation_heating_rate(1e-5, 8000.0, 1.7415e-4, 0.5, 3.0, 1.0) == pytest.approx(
        1.7415e-4 * math.sqrt(1e-5) * 8000.0 ** 3)
    assert aero.load_factor(3.0, 4.0, 10.0) == pytest.approx(0.5)


def test_empirical_costate_at_reference_point():
    """Seed-000 extraction Sec. 4.3 [D]: (4.28) gives -5.154396e-6 km/s^3, a = 0.77316, b = -2.5772e-3."""
    assert lambda_r_empirical(8200.0, -0.02, 90e3, 300.0) == pytest.approx(-5.154396e-6, rel=1e-6)
    a, b = approximate_law_coefficients(8200.0, -0.02, 90e3, 300.0)
    assert a == pytest.approx(0.77316, abs=5e-6)
    assert b == pytest.approx(-2.5772e-3, abs=5e-8)
    assert a + b * 300.0 == pytest.approx(0.0, abs=1e-12)  # (4.23) passes through (tf, 0)


def test_planar_equations_match_seed_000():
    """With sigma = phi = psi = 0 and constant g, Vinh's equations are seed-000 eq. (2.7)."""
    r, v, gamma, u = 6468.1e3, 8200.0, -0.02, 0.7
    rho = exponential_density(r - 6378.1e3, 1.752, 0.0, 7045.0)
    d = point_mass.derivatives([r, 0.0, 0.0, v, gamma, 0.0], rho, u, 0.0, 0.1 / 300.0, 0.0, 0, 9.81, 0.0)
    K = 1.752 * 0.1 / 600.0
    assert d[0] == pytest.approx(v * math.sin(gamma))
    assert d[3] == pytest.approx(-9.81 * math.sin(gamma) - K * math.exp(-(r - 6378.1e3) / 7045.0) * v * v, rel=1e-12)
    assert d[4] == pytest.approx((v / r - 9.81 / v) * math.cos(gamma) + u / v)
    assert d[2] == 0.0 and d[5] == 0.0


def test_rk4_converges_fourth_order():
    """Halving the RK4 substep divides the error of a 100 s arc by about 16."""
    args = (1e-6, 0.5, 0.0, 3e-4, 0.3, 1, 9.81, 3.986004418e14)
    x0 = [6478e3, 0.0, 0.1, 7800.0, -0.01, 0.2]
    exact = point_mass.integrate(x0, 100.0, 0.05, args)
    e1 = abs(point_mass.integrate(x0, 100.0, 10.0, args)[0] - exact[0])
    e2 = abs(point_mass.integrate(x0, 100.0, 5.0, args)[0] - exact[0])
    assert 12.0 < e1 / e2 < 20.0


def test_actuator_pass_through_lag_rate_and_saturation():
    assert advance(0.0, 2.0, 0.1, 0.0, math.inf) == 2.0
    assert advance(0.0, 1.0, 0.5, 0.5, math.inf) == pytest.approx(1.0 - math.exp(-1.0))
    assert advance(0.0, 1.0, 0.1, 0.0, 2.0) == pytest.approx(0.2)
    assert saturate(5.0, -1.0, 1.0) == 1.0 and saturate(-5.0, -1.0, 1.0) == -1.0


def test_planar_rk4_step_equals_the_general_step_to_the_bit():
    """`point_mass._rk4_planar` (phi = psi = sigma = 0) gives exactly the general RK4 step's
    numbers: the vehicle FMUs' fast path changes no result."""
    import math
    import random

    from aotv_cosim.physics import point_mass as pm

    rng = random.Random(1)
    for _ in range(2000):
        x = [6.378e6 + rng.uniform(6e4, 1.2e5), rng.uniform(-1, 1), 0.0, rng.uniform(3e3, 9e3),
             rng.uniform(-0.1, 0.1), 0.0]
        rho, lift, cl, cd = rng.uniform(0, 1e-3), rng.uniform(-5, 5), rng.uniform(0, 1e-3), rng.uniform(0, 1e-3)
        gravity, heading, dt = rng.choice([0, 1]), rng.choice([0, 1]), rng.uniform(0.01, 1.0)
        held = (rho, lift, cl, cd, math.cos(0.0), math.sin(0.0), gravity, 9.81, 3.986e14, heading)
        half = 0.5 * dt
        a = pm._rates(x, *held)
        b = pm._rates([xi + half * ai for xi, ai in zip(x, a)], *held)
        c = pm._rates([xi + half * bi for xi, bi in zip(x, b)], *held)
        d = pm._rates([xi + dt * ci for xi, ci in zip(x, c)], *held)
        general = [xi + dt / 6.0 * (ai + 2.0 * bi + 2.0 * ci + di) for xi, ai, bi, ci, di in zip(x, a, b, c, d)]
        assert pm._rk4_planar(x, dt, rho, lift, cl, cd, gravity, 9.81, 3.986e14) == general


def test_tauber_sutton_radiative_heating_at_table_points():
    """Tauber & Sutton (1991) eq. (1), air: q = 4.736e4 r_n^a rho^1.22 f(V) W/cm^2, f(10 km/s) = 35,
    f(10.25 km/s) = 55 (Table 1, linear between), a = 1.072e6 V^-1.88 rho^-0.325 capped by r_n."""
    rho = 2.0e-4
    a = 1.072e6 * 10000.0 ** -1.88 * rho ** -0.325
    assert 0.5 < a < 0.6  # so the 1 <= r_n <= 2 m cap (0.6) leaves it, the r_n > 2 m cap (0.5) acts
    assert aero.radiative_heating_rate(rho, 10000.0, 1.5) == pytest.approx(
        4.736e4 * 1.5 ** a * rho ** 1.22 * 35.0 * 1e4, rel=1e-12)
    assert aero.radiative_heating_rate(rho, 10000.0, 2.5) == pytest.approx(
        4.736e4 * 2.5 ** 0.5 * rho ** 1.22 * 35.0 * 1e4, rel=1e-12)
    a_mid = 1.072e6 * 10125.0 ** -1.88 * rho ** -0.325
    assert aero.radiative_heating_rate(rho, 10125.0, 1.5) == pytest.approx(
        4.736e4 * 1.5 ** a_mid * rho ** 1.22 * 45.0 * 1e4, rel=1e-12)


def test_tauber_sutton_exponent_caps():
    """a <= 1 always, <= 0.6 for 1 <= r_n <= 2 m (2 m included), <= 0.5 above 2 m."""
    thin, v = 1.0e-7, 10000.0  # raw a far above 1
    assert aero.radiative_exponent(thin, v, 0.5) == 1.0
    assert aero.radiative_exponent(thin, v, 1.0) == aero.radiative_exponent(thin, v, 2.0) == 0.6
    assert aero.radiative_exponent(thin, v, 2.01) == aero.radiative_exponent(thin, v, 4.0) == 0.5
    dense = 1.0e-2
    assert aero.radiative_exponent(dense, v, 0.5) == pytest.approx(1.072e6 * v ** -1.88 * dense ** -0.325)


def test_tauber_sutton_outside_its_range():
    """0 below the table's 9000 m/s and without air; f held at 2040 above 16 km/s; the range flag."""
    assert aero.radiative_heating_rate(1e-4, 8999.0, 1.0) == 0.0
    assert aero.radiative_heating_rate(0.0, 12000.0, 1.0) == 0.0
    assert aero.radiative_heating_rate(1e-4, 9000.0, 1.0) > 0.0
    # r_n = 1 m: r_n^a = 1 whatever a, so only f(V) differs between the speeds
    assert aero.radiative_heating_rate(1e-4, 17000.0, 1.0) == aero.radiative_heating_rate(1e-4, 16000.0, 1.0)
    assert aero.radiative_heating_in_range(1e-4, 10300.0, 2.0)
    assert not aero.radiative_heating_in_range(1e-4, 9700.0, 2.0)  # below 10 km/s: table, not the fit
    assert not aero.radiative_heating_in_range(3e-5, 10300.0, 2.0)
    assert not aero.radiative_heating_in_range(1e-4, 10300.0, 4.0)
