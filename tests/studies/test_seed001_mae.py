"""Seed 001: MRRV data, the MAE toy problem (Secs. 2.2, 4.1.2) and the zeroth-order MAE
guidance (Sec. 3, App. B) of Calise & Melamed, NASA CR-194523.

Expected values: extraction = `shared/research/seed-001-nasa-mae.md`; [R] the report, [D] derived
by hand in the extraction, [V] the extraction author's independent prototype (evidence, not
gospel). Angles in the report are in degrees; the code works in rad.
"""

import itertools
import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

from aotv_cosim.guidance import mae, mae_first_order, mae_solution, mae_toy
from aotv_cosim.guidance.mae_guided import MaeGuidanceLaw
from aotv_cosim.physics import mrrv, orbit, point_mass

D = math.radians
MODEL = mae.MaeModel()
ENTRY_STATE = mae.State(MODEL.r_earth + 60.0e3, 7851.0, D(-1.35), 0.0)
TARGETS = mae.Targets(60.0e3, D(1.0), D(20.0))


# --- MRRV data (Sec. 3.7.1) ----------------------------------------------------------------

def test_mrrv_polar_and_derived_constants():
    """[D] extraction 3.2: C_D* = 0.0640135, C_D0 = C_D*/2, K = C_D*/(2 C_L*^2) = 1.40003,
    1/(2 sqrt(C_D0 K)) = E* = 2.362, K_w = 1.3756821 m^3/kg; polar (3.10) at lambda = 1 is C_D*."""
    assert pytest.approx(0.0640135, abs=5e-8) == mrrv.CD_STAR
    k_polar = mrrv.CD_STAR / (2.0 * mrrv.CL_STAR ** 2)
    assert k_polar == pytest.approx(1.40003, abs=5e-6)
    assert 1.0 / (2.0 * math.sqrt(0.5 * mrrv.CD_STAR * k_polar)) == pytest.approx(2.362, rel=1e-12)
    assert pytest.approx(1.3756821, abs=5e-8) == mrrv.K_W
    assert MODEL.k_w == pytest.approx(mrrv.K_W, rel=1e-15)
    assert mrrv.drag_coefficient(1.0) == pytest.approx(mrrv.CD_STAR, rel=1e-15)
    cl_s_m, cd_s_m = mrrv.coefficients_per_mass(0.5)
    assert cl_s_m == pytest.approx(0.5 * 0.1512 * 11.69 / 4898.7, rel=1e-15)
    assert cd_s_m == pytest.approx(0.5 * mrrv.CD_STAR * 1.25 * 11.69 / 4898.7, rel=1e-15)


def test_atmosphere_anchor_and_inverse():
    """Extraction A2: rho(60 km) = 3.0967559e-4 kg/m^3 (US-1976) with H_s = 7625.4 m [R 3.7.1],
    one e-fold per scale height (3.8), and altitude_at_density inverts it."""
    assert mrrv.density(60.0e3) == pytest.approx(3.0967559e-4, rel=1e-15)
    assert mrrv.density(60.0e3 - 7625.4) == pytest.approx(3.0967559e-4 * math.e, rel=1e-12)
    assert mrrv.altitude_at_density(mrrv.density(44.0e3)) == pytest.approx(44.0e3, abs=1e-8)


def test_inclination_and_loh_term():
    """Extraction 2.7: i = arccos(cos phi cos psi), [V] phi 2.46 deg, psi 20 deg -> 20.145 deg.
    Loh's term: with gamma = 0, dgamma/dpsi of (3.5)/(3.6) equals [delta + eps Mbar]/sigma (3.47)."""
    assert math.degrees(orbit.inclination(D(2.46), D(20.0))) == pytest.approx(20.145, abs=2e-3)
    r, v, lam, bank = MODEL.r_earth + 50.0e3, 7000.0, 1.0, D(75.0)
    rho = mrrv.density(50.0e3)
    cl, cd = mrrv.coefficients_per_mass(lam)
    dx = point_mass.derivatives([r, 0.0, 0.0, v, 0.0, 0.0], rho, 0.0, cl, cd, bank,
                                point_mass.GRAVITY_INVERSE_SQUARE, 9.81, MODEL.mu_earth)
    loh = mrrv.loh_term(r, v, rho, MODEL.mu_earth)
    sigma, delta = lam * math.sin(bank), lam * math.cos(bank)
    assert dx[4] / dx[5] == pytest.approx((delta + loh) / sigma, rel=1e-12)


# --- Toy problem (Secs. 2.2, 4.1.2; extraction Sec. 7) ---------------------------------------

TOY_CASES = [(0.0, 0.0), (0.2, 0.5)]   # [R] Sec. 2.2.7: case A (t_i, x_i), case B


@pytest.mark.parametrize("t_i, x_i", TOY_CASES)
def test_toy_exact_solution_solves_the_ode(t_i, x_i):
    """(2.13) with u = 1 integrated numerically matches the corrected (2.14) (A5) to 1e-9."""
    eps = 0.1
    t = np.linspace(t_i, 1.0, 11)
    sol = solve_ivp(lambda s, x: x + np.exp(-s / eps) / eps, (t_i, 1.0), [x_i], t_eval=t,
                    method="DOP853", rtol=1e-13, atol=1e-14)
    np.testing.assert_allclose(sol.y[0], mae_toy.exact_state(t, x_i, t_i, eps), atol=1e-9)


@pytest.mark.parametrize("t_i, x_i", TOY_CASES)
def test_toy_composite_meets_initial_condition_and_costate_is_exact(t_i, x_i):
    """[R] Sec. 2.2.7: the composite satisfies x(t_i) = x_i; extraction 7.3/7.4: lambda_0^c (2.37)
    equals the exact lambda (2.15)."""
    assert mae_toy.composite_state(t_i, x_i, t_i, 0.1) == pytest.approx(x_i, abs=1e-12)
    t = np.linspace(t_i, 1.0, 9)
    np.testing.assert_allclose(mae_toy.composite_costate(t), mae_toy.exact_costate(t), rtol=1e-14)


TOY_TABLE = [  # extraction 7.5 [V]: case, t, exact, composite, outer, inner (eps = 0.1)
    ("A", 0.00, 0.000000, 0.000000, 1.000000, 0.000000),
    ("A", 0.05, 0.404309, 0.444740, 1.051271, 0.393469),
    ("A", 0.10, 0.670265, 0.737291, 1.105171, 0.632121),
    ("A", 0.20, 0.987334, 1.086067, 1.221403, 0.864665),
    ("A", 0.50, 1.492712, 1.641983, 1.648721, 0.993262),
    ("A", 1.00, 2.471124, 2.718236, 2.718282, 0.999955),
    ("B", 0.20, 0.500000, 0.500000, 0.635335, 0.384833),
    ("B", 0.30, 0.643296, 0.652367, 0.702154, 0.470381),
    ("B", 0.50, 0.834880, 0.850875, 0.857613, 0.513431),
    ("B", 0.75, 1.079369, 1.100644, 1.101197, 0.519615),
    ("B", 1.00, 1.386542, 1.413919, 1.413965, 0.520123),
]


@pytest.mark.parametrize("case, t, exact, comp, outer, inner", TOY_TABLE)
def test_toy_reference_table(case, t, exact, comp, outer, inner):
    """Extraction 7.5 [V] values (printed to 6 decimals, so compared to 6e-7)."""
    t_i, x_i = TOY_CASES[0] if case == "A" else TOY_CASES[1]
    eps = 0.1
    got = (mae_toy.exact_state(t, x_i, t_i, eps), mae_toy.composite_state(t, x_i, t_i, eps),
           mae_toy.outer_state(t, x_i, t_i, eps), mae_toy.inner_state(t / eps, x_i, t_i, eps))
    np.testing.assert_allclose(got, (exact, comp, outer, inner), atol=6e-7)


@pytest.mark.parametrize("t_i, x_i, p_exact, p0, p1", [
    (0.0, 0.0, 2.47112403, 2.71823643, 2.44642059),
    (0.2, 0.5, 1.38654211, 1.41391928, 1.37714367),
])
def test_toy_return_functions(t_i, x_i, p_exact, p0, p1):
    """Extraction 7.5 [V] return functions at eps = 0.1 (8 decimals). P_1^c (4.44) also equals
    P_0^c - eps * int_{t_i/eps}^{1/eps} [R_1^i - R_1^i_inf] dtau with (4.42)-(4.43), by
    quadrature, to 1e-9."""
    eps = 0.1
    assert mae_toy.return_exact(x_i, t_i, eps) == pytest.approx(p_exact, abs=6e-9)
    assert mae_toy.return_zeroth(x_i, t_i, eps) == pytest.approx(p0, abs=6e-9)
    assert mae_toy.return_first(x_i, t_i, eps) == pytest.approx(p1, abs=6e-9)
    a = mae_toy.common_part(x_i, t_i, eps)
    integral, _ = quad(lambda tau: -math.e * (a - math.exp(-tau)) + math.e * a, t_i / eps, 1.0 / eps,
                       epsabs=1e-14, epsrel=1e-13)
    assert mae_toy.return_first(x_i, t_i, eps) == pytest.approx(
        mae_toy.return_zeroth(x_i, t_i, eps) - eps * integral, abs=1e-9)


def test_toy_first_order_error_is_uniformly_order_eps_squared():
    """(4.47)-(4.49): max_{t_i in [0,1]} |P - P_1^c| = O(eps^2). Extraction 7.5 [V] (x_i = 0.3):
    2.470e-2, 6.47e-3, 1.066e-3, 2.69e-4 for eps = 0.1, 0.05, 0.02, 0.01; the ratio to eps^2
    rises toward e. max |P - P_0^c| is only O(eps): 0.247 at eps = 0.1."""
    expected = {0.1: 2.470e-2, 0.05: 6.47e-3, 0.02: 1.066e-3, 0.01: 2.69e-4}
    ratios = []
    for eps, err in expected.items():
        got = mae_toy.max_first_order_error(eps, 0.3)
        assert got == pytest.approx(err, rel=2e-3)
        ratios.append(got / eps ** 2)
    assert all(a < b < math.e for a, b in itertools.pairwise(ratios))
    t_i = np.linspace(0.0, 1.0, 20001)
    err0 = np.max(np.abs(mae_toy.return_exact(0.3, t_i, 0.1) - mae_toy.return_zeroth(0.3, t_i, 0.1)))
    assert err0 == pytest.approx(0.247, abs=5e-4)


# --- Zeroth-order MAE, open loop (Secs. 3.6-3.7) --------------------------------------------

@pytest.fixture(scope="module")
def nominal():
    """Cold-start entry solve for the Sec. 3.7.2 case (gamma_i = -1.35 deg, extraction A1)."""
    return mae.solve(ENTRY_STATE, TARGETS)


def test_nominal_converges_and_meets_all_boundary_conditions(nominal):
    """Extraction S1: the 4 conditions (3.124) to 1e-10 and the heading conditions (3.120)-(3.121)
    through w_0^i(psi_i) = w_i, w_0^i(psi_f) = w_f [R 3.7.1]."""
    assert nominal.converged and nominal.mode == mae.ENTRY
    k = nominal.constants
    assert np.max(np.abs(mae.boundary_residuals(k, ENTRY_STATE, TARGETS, MODEL.r_earth))) < 1e-10
    assert k.inner.w(ENTRY_STATE.psi) == pytest.approx(MODEL.w_at_radius(ENTRY_STATE.r), rel=1e-12)
    w_f = MODEL.w_at_radius(MODEL.r_earth + TARGETS.z_f)
    assert k.inner.w(TARGETS.psi_f) == pytest.approx(w_f, rel=1e-12)
    assert k.inner.w(k.psi_l) == pytest.approx(0.0, abs=1e-15)
    assert k.inner.w(k.psi_r) == pytest.approx(0.0, abs=1e-15)


def test_nominal_expansion_parameter(nominal):
    """[R] Sec. 3.7.2: eps = 1/(beta r_s) = 11.87e-4 (+-0.02e-4, extraction S1). [V] 11.8736e-4."""
    assert nominal.constants.eps == pytest.approx(11.87e-4, abs=0.02e-4)


def test_nominal_common_headings(nominal):
    """[R] Sec. 3.7.1 (Fig. 3.2): left/right common parts of psi_0^i are -1.10 and 20.75 deg
    (+-0.35 deg, extraction S1). We get -1.078 and 20.518 deg, as [V] 9.1 does: psi_R is 0.23 deg
    below the report's value, which the extraction attributes to the unknown density anchor (A2;
    a 30 km anchor gives 20.62 deg)."""
    k = nominal.constants
    assert math.degrees(k.psi_l) == pytest.approx(-1.10, abs=0.35)
    assert math.degrees(k.psi_r) == pytest.approx(20.75, abs=0.35)


def test_nominal_lowest_point_heading(nominal):
    """[R] Sec. 4.3 (Fig. 4.2): the entry phase spans headings 0 to 11.5 deg (+-0.3 deg, extraction
    S1); psi_s from (3.113) corrected (A9). [V] 11.544 deg."""
    assert math.degrees(nominal.constants.psi_s) == pytest.approx(11.5, abs=0.3)


def test_nominal_matches_prototype_constants(nominal):
    """[V] extraction 9.1 golden numbers (printed to 6-7 significant digits)."""
    k = nominal.constants
    i = k.inner
    got = [i.sigma, i.k1, i.k3, i.p_v, i.p_w, i.p_psi, k.w_s, k.r_s, k.left.u0, k.right.u0,
           k.left.a1, k.left.a2, k.right.a1, k.right.a2, i.v_l]
    ref = [0.976725, -1.087792, -0.0221675, -0.3196593, 0.6634495, 0.624438, 3.47145e-3, 6422140.0,
           1.014106, 0.731423, 1.025067, 0.568983, 4.516594, 5.097009, -42.41615]
    np.testing.assert_allclose(got, ref, rtol=2e-6)
    assert math.degrees(k.left.gamma0) == pytest.approx(-1.2595, abs=1e-4)
    assert math.degrees(k.right.gamma0) == pytest.approx(2.7354, abs=1e-4)


def test_open_loop_composite_controls_and_end_points(nominal):
    """[R] Sec. 3.7.2: 'lambda is always near 1.0', 'mu is always near 90 deg'; extraction S1
    bounds lambda in [0.95, 1.05], mu in [70, 92] deg along the composite. The composite meets
    the boundary data (z = 60 km, 7851 m/s, -1.35 deg; 60 km, +1 deg, P_u = 1 (3.116)).
    [V] 9.2: lambda 0.9837 / mu 90.05 deg at entry, 1.0199 / 80.85 deg at exit, V_f 6742.63 m/s."""
    k = nominal.constants
    h = mae_solution.open_loop(k, np.linspace(0.0, D(20.0), 401), MODEL.r_earth)
    assert np.all((h.lam >= 0.95) & (h.lam <= 1.05))
    assert np.all((np.degrees(h.bank) >= 70.0) & (np.degrees(h.bank) <= 92.0))
    np.testing.assert_allclose([h.z[0], h.v[0], h.gamma[0]], [60.0e3, 7851.0, D(-1.35)], rtol=1e-9)
    np.testing.assert_allclose([h.z[-1], h.gamma[-1], h.p_u[-1]], [60.0e3, D(1.0), 1.0], rtol=1e-9)
    np.testing.assert_allclose([h.lam[0], h.lam[-1]], [0.9837, 1.0199], atol=5e-5)
    np.testing.assert_allclose(np.degrees([h.bank[0], h.bank[-1]]), [90.05, 80.85], atol=5e-3)
    assert h.v[-1] == pytest.approx(6742.63, abs=0.01)


def test_app_b1_claims(nominal):
    """[R] App. B.1: the right outer P_u at h = 0 is ~1 ('verified in Fig. 3.7') and dv_0^i/dpsi
    is ~2.0 ('verified from Fig. 3.5'). [V] 6.4: P_uR = 1.032, mean dv/dpsi = 2.048."""
    k = nominal.constants
    assert k.right.p_u0 == pytest.approx(1.032283, abs=1e-5)
    mean_slope = (k.inner.v(k.psi_r) - k.inner.v(k.psi_l)) / (k.psi_r - k.psi_l)
    assert mean_slope == pytest.approx(2.048, abs=1e-3)


def test_control_law_is_a_stationary_maximum_of_the_hamiltonian():
    """(3.26)-(3.27) are H_lambda = H_mu = 0 of (3.25); the chosen branch maximizes the
    time-domain Hamiltonian H * sin(gamma) (extraction 2.6), for gamma on both sides."""
    e_star, b, eps, h = mrrv.E_STAR, 3.5e-3, 1.19e-3, 1.0e-3
    u, p_u, p_g, p_psi = 0.9, 0.85, 0.09, 0.62

    def ham_time(lam, bank, gamma):
        a = b * math.exp(-h / eps) / (eps * math.sin(gamma))
        ham = ((-a * u * (1 + lam ** 2) / e_star - 2 / (1 + h) ** 2) * p_u
               + (a * lam * math.cos(bank) + (1 / (1 + h) - 1 / (u * (1 + h) ** 2)) / math.tan(gamma)) * p_g
               + a * lam * math.sin(bank) / math.cos(gamma) * p_psi)
        return ham * math.sin(gamma)

    for gamma in (D(-1.2), D(2.0)):
        lam, bank = mae_solution.control_from_costates(u, gamma, p_u, p_g, p_psi, e_star)
        assert math.tan(bank) == pytest.approx(p_psi / (p_g * math.cos(gamma)), rel=1e-12)
        assert lam == pytest.approx(e_star * (p_g * math.cos(bank) + p_psi * math.sin(bank) / math.cos(gamma))
                                    / (2 * u * p_u), rel=1e-12)
        best = ham_time(lam, bank, gamma)
        for dl, db in [(1e-3, 0), (-1e-3, 0), (0, 1e-3), (0, -1e-3)]:
            assert ham_time(lam + dl, bank + db, gamma) < best


def test_warm_resolve_and_failure_keeps_last_constants(nominal):
    """Sec. 3.8.1: warm starts from the previous constants; extraction A19: when the exit-phase
    problem has no solution (psi_f - psi below ~1 deg) the last converged constants are kept."""
    again = mae.solve(ENTRY_STATE, TARGETS, nominal)
    assert again.converged and again.iterations <= 1
    late = mae.State(MODEL.r_earth + 55.0e3, 6790.0, D(1.3), D(19.8))
    failed = mae.solve(late, TARGETS, nominal)
    assert not failed.converged and failed.mode == mae.EXIT
    assert failed.constants is nominal.constants


# --- Zeroth-order guided closed loop (Sec. 3.8) ---------------------------------------------

def _reduced_rates(x, lam, bank):
    """(3.1)-(3.6) without the tan(phi) term (extraction 2.7): point_mass with phi held at 0."""
    z = x[0] - MODEL.r_earth
    cl, cd = mrrv.coefficients_per_mass(lam)
    dx = point_mass.derivatives([x[0], x[1], 0.0, x[3], x[4], x[5]], mrrv.density(z), 0.0, cl, cd,
                                bank, point_mass.GRAVITY_INVERSE_SQUARE, 9.81, MODEL.mu_earth)
    return np.array([dx[0], dx[1], 0.0, dx[3], dx[4], dx[5]])


def fly_guided(dt=0.1, period=5.0, **options):
    """RK4 flight with the control law at every stage and MAE re-solves every `period` s
    ([R] Sec. 3.8.2: 5 s), stopped at the 60 km exit crossing. options go to MaeGuidanceLaw.
    Returns (final state, law)."""
    law = MaeGuidanceLaw(TARGETS, MODEL, period, **options)
    x = np.array([ENTRY_STATE.r, 0.0, 0.0, ENTRY_STATE.v, ENTRY_STATE.gamma, ENTRY_STATE.psi])
    t = 0.0
    while t < 400.0:
        law.update(t, mae.State(x[0], x[3], x[4], x[5]))

        def rate(y):
            return _reduced_rates(y, *law.command(mae.State(y[0], y[3], y[4], y[5])))
        k1 = rate(x)
        k2 = rate(x + 0.5 * dt * k1)
        k3 = rate(x + 0.5 * dt * k2)
        k4 = rate(x + dt * k3)
        x_new = x + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
        t += dt
        if x_new[4] > 0.0 and x_new[0] >= MODEL.r_earth + TARGETS.z_f:
            a = (MODEL.r_earth + TARGETS.z_f - x[0]) / (x_new[0] - x[0])
            return x + a * (x_new - x), law
        x = x_new
    raise AssertionError("no exit within 400 s")


@pytest.fixture(scope="module")
def guided():
    return fly_guided()


def test_guided_flight_meets_exit_conditions(guided):
    """Extraction S3: gamma_f within +-0.5 deg of 1 deg, psi_f within +-1 deg of 20 deg, V_f >= 6690
    m/s ([V] 9.4 floor). [R] Sec. 3.8.2 reports 6736 m/s guided, 15 m/s below its 6751 m/s
    optimum: NOT reproduced. Here (reduced model, RK4 0.1 s, control at every stage) V_f = 6702.6
    m/s, gamma_f = 0.93 deg, psi_f = 20.36 deg: 32 m/s below our optimum 6734.6 m/s. [V] 9.4 gets
    6690.5-6702.4 m/s depending on the exit-phase r_s and the inner u (A17, A18); the loss sits in
    the terminal phase, where the exit-mode MAE has no solution (A19) and the heading overshoots."""
    xf, _ = guided
    assert math.degrees(xf[4]) == pytest.approx(1.0, abs=0.5)
    assert math.degrees(xf[5]) == pytest.approx(20.0, abs=1.0)
    assert xf[3] >= 6690.0


def test_guided_resolves_converge_until_the_terminal_phase(guided):
    """Sec. 3.8.1 / A18-A19: solves every 5 s; every entry-phase and exit-phase re-solve converges
    while more than 1 deg of heading remains; later failures keep the last converged constants."""
    _, law = guided
    times = [t for t, _, _ in law.solutions]
    np.testing.assert_allclose(np.diff(times), 5.0, atol=1e-6)
    modes = [s.mode for _, _, s in law.solutions]
    assert modes[0] == mae.ENTRY and modes[-1] == mae.EXIT
    assert modes == sorted(modes, key=lambda m: m == mae.EXIT)
    previous = None
    for _, state, s in law.solutions:
        if TARGETS.psi_f - state.psi > D(1.0):
            assert s.converged, (math.degrees(state.psi), s.residual)
        if not s.converged:
            assert s.constants is previous.constants
        previous = s
    assert 0 < law.failures < len(law.solutions)


def test_stop_turn_option_ends_on_the_target_heading(guided):
    """mae_guided option (not in the report): only vertical lift once psi >= psi_f, so the
    heading ends within one RK4 step of turn of 20 deg and no speed is spent on overshoot
    (V_f 6707.4 m/s vs 6702.6 m/s, gamma_f 0.97 deg)."""
    xf, _ = fly_guided(stop_turn_at_psi_f=True)
    assert math.degrees(xf[5]) == pytest.approx(20.0, abs=0.01)
    assert math.degrees(xf[4]) == pytest.approx(1.0, abs=0.5)
    assert xf[3] > guided[0][3]


# --- First-order HJB correction (Sec. 4, experimental) ---------------------------------------

def test_first_order_costates_at_entry(nominal):
    """Extraction 9.5 [V]: the finite-difference gradient of the zeroth-order return function
    u_f^c at the entry state is (0.764, 0.0495, 0.635) (checks the gradient machinery with Q = 0).
    With the first-order term eps Q of (4.58) we get (0.779, 0.063, 0.634): P_u and P_psi equal the
    optimal costates of [V] 9.3 (0.779, 0.634) to 1e-3, while P_gamma overshoots the optimal 0.027
    from the zeroth-order composite -0.0005: 'initially the first order calculation overcorrects
    the zeroth order solution' ([R] Sec. 4.3, Fig. 4.2)."""
    state = ENTRY_STATE
    zeroth = mae_first_order.first_order_costates(nominal, state, TARGETS, MODEL, order=0)
    np.testing.assert_allclose(zeroth, [0.764, 0.0495, 0.635], atol=6e-4)
    p_u, p_gamma, p_psi = mae_first_order.first_order_costates(nominal, state, TARGETS, MODEL)
    assert [p_u, p_psi] == pytest.approx([0.779, 0.634], abs=1e-3)
    composite = mae_solution.composite_costates(nominal.constants, state.r, state.v, state.gamma, state.psi)
    assert composite[2] < 0.027 < p_gamma


def test_first_order_guided_flight_is_not_adopted():
    """The first-order law flown (our experiment; the report did not fly it): V_f = 6729.4 m/s
    but gamma_f = 1.89 deg and psi_f = 19.36 deg, i.e. the exit flight-path condition (+-0.5 deg)
    is missed and 25 of 48 re-solves fail; hence it stays an option, off by default."""
    xf, law = fly_guided(first_order=True)
    assert abs(math.degrees(xf[4]) - 1.0) > 0.5
    assert law.failures > len(law.solutions) // 3


def test_reduced_heading_equation_drops_only_the_tan_phi_term():
    """point_mass HEADING_REDUCED: (3.6) without -V^2 cos(gamma) cos(psi) tan(phi)/r, i.e. eq. (3.23)
    in time form (extraction 2.5, 2.7); identical to the full model at phi = 0."""
    cl, cd = mrrv.coefficients_per_mass(1.0)
    args = (mrrv.density(50e3), 0.0, cl, cd, D(80.0), point_mass.GRAVITY_INVERSE_SQUARE, 9.81,
            MODEL.mu_earth)
    x = [MODEL.r_earth + 50e3, 0.1, D(2.0), 7000.0, D(0.5), D(15.0)]
    full = point_mass.derivatives(x, *args)
    reduced = point_mass.derivatives(x, *args, point_mass.HEADING_REDUCED)
    assert reduced[:5] == full[:5]
    coupling = x[3] * math.cos(x[4]) * math.cos(x[5]) * math.tan(x[2]) / x[0]
    assert reduced[5] - full[5] == pytest.approx(coupling, rel=1e-12)
    x[2] = 0.0
    assert point_mass.derivatives(x, *args, point_mass.HEADING_REDUCED) == point_mass.derivatives(x, *args)
