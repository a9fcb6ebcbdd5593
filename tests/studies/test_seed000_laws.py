"""Seed 000 feedback laws: LQR (Ch. 5, eqs. 5.5-5.18), robust (Ch. 7, eqs. 7.1-7.5) and
adaptive (Sec. 8.2, eqs. 8.5-8.9, 8.17), in closed loop around the optimal nominal of (3.21).

Expected values: extraction = `shared/research/seed-000-aotv-thesis.md`; [T] thesis, [V] the
extraction author's independent prototype (evidence, not gospel). The thesis gives no initial
perturbation for Tables 5.1/5.2, so the LQR checks are the qualitative ones of extraction Sec. 8
item 13 on a documented perturbation (dh0 = -1 km).

Closed loop here mimics the co-simulation: RK4 on (2.7) with step 0.1 s, the command
u = u_nominal(t_k) + du(x_k) held over each step (extraction Sec. 6.8 [V] setup).
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import expm, solve_continuous_lyapunov

from aotv_cosim.guidance import adaptive, lqr, robust
from aotv_cosim.guidance.optimal_bvp import solve_min_effort
from aotv_cosim.guidance.predictive import solve_predictive
from aotv_cosim.guidance.time_linear import time_linear_integrals
from aotv_cosim.physics.planar import (
    ENTRY_000, EXIT_000, K_BALL_000, TF_000, AotvConstants, adaptive_model_matrix, dynamics,
    input_b, jacobian_a, km_state,
)

DT = 0.1
T_GRID = np.arange(0.0, TF_000 + DT / 2, DT)


@pytest.fixture(scope="module")
def nominal():
    """Optimal nominal of Table 4.1 sampled on T_GRID: (h, v, gamma) SI (3, n) and u (n,)."""
    sol = solve_min_effort()
    x = sol.state(T_GRID)
    return np.array([x[0] - AotvConstants.si().r_earth, x[1], x[2]]), sol.u(T_GRID)


def _closed_loop(nominal, law, k_factor=1.0, dx0=(0.0, 0.0, 0.0)):
    """Fly (2.7) with K = k_factor K_nom from the entry + dx0 (SI); law(i, state_si) -> du m/s^2.

    Returns (exit error (dh m, dv m/s, dgamma rad), max |u| m/s^2, min h m, int u^2 m^2/s^3)."""
    _x_nom, u_nom = nominal
    c = AotvConstants.si(K_BALL_000 * k_factor)
    x = np.array([c.r_earth + ENTRY_000[0] + dx0[0], ENTRY_000[1] + dx0[1], ENTRY_000[2] + dx0[2]])
    u_max, h_min, effort = 0.0, np.inf, 0.0
    for i in range(len(T_GRID) - 1):
        state = (x[0] - c.r_earth, x[1], x[2])
        u = u_nom[i] + law(i, state)
        u_max, h_min, effort = max(u_max, abs(u)), min(h_min, state[0]), effort + u * u * DT
        k1 = dynamics(x, u, c)
        k2 = dynamics(x + DT / 2 * k1, u, c)
        k3 = dynamics(x + DT / 2 * k2, u, c)
        k4 = dynamics(x + DT * k3, u, c)
        x = x + DT / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    error = np.array([x[0] - c.r_earth - EXIT_000[0], x[1] - EXIT_000[1], x[2] - EXIT_000[2]])
    return error, u_max, min(h_min, x[0] - c.r_earth), effort


def _percent(error):
    """% exit errors 100 (x(tf) - x_f)/x_f in (h, v, gamma) (extraction Sec. 7 recommendation)."""
    return 100.0 * error / np.array(EXIT_000)


@pytest.fixture(scope="module")
def frozen(nominal):
    """(A, B) of (5.2)/(5.3) frozen at t = 0 on the nominal (Ch. 5), km-s."""
    x_nom, u_nom = nominal
    return lqr.frozen_linearization(x_nom[:, 0], u_nom[0])


def test_infinite_horizon_gain_is_optimal(frozen):
    """(5.7)-(5.9) with the weights of (5.6): A - B k^T is stable ((A, B) controllable, (A, sqrt Q)
    observable, Ch. 5), and k is stationary for its own cost: with M the closed-loop cost matrix,
    (A - B k^T)^T M + M (A - B k^T) = -(Q + k R k^T), the gain equals R^-1 B^T M (5.8), so M
    solves the algebraic Riccati equation (5.9)."""
    a_mat, b_vec = frozen
    k = lqr.infinite_horizon_gain(a_mat, b_vec)
    closed = a_mat - np.outer(b_vec, k)
    assert np.all(np.linalg.eigvals(closed).real < 0)
    m0 = solve_continuous_lyapunov(closed.T, -(lqr.Q_INFINITE + lqr.R_INFINITE * np.outer(k, k)))
    np.testing.assert_allclose(k, b_vec @ m0 / lqr.R_INFINITE, rtol=1e-6)
    care = a_mat.T @ m0 + m0 @ a_mat - np.outer(m0 @ b_vec, b_vec @ m0) / lqr.R_INFINITE + lqr.Q_INFINITE
    assert np.max(np.abs(care)) < 1e-6 * np.max(lqr.Q_INFINITE)


def test_terminal_riccati_matches_backward_integration(frozen):
    """(5.16)-(5.18): M0 = E F^-1 from the Hamiltonian exponential equals the backward solution
    of the Riccati ODE (5.14) with M0(tf) = V (5.15), weights (5.11); k(tf) = B^T V / R."""
    a_mat, b_vec = frozen
    bbt = np.outer(b_vec, b_vec) / lqr.R_TERMINAL

    def riccati(_t, m):
        m = m.reshape(3, 3)
        return -(a_mat.T @ m + m @ a_mat - m @ bbt @ m + lqr.Q_TERMINAL).ravel()

    t = np.array([0.0, 100.0, 200.0, 290.0, TF_000])
    ode = solve_ivp(riccati, (TF_000, 0.0), lqr.V_TERMINAL.ravel(), t_eval=t[::-1], rtol=1e-11,
                    atol=1e-14, method="DOP853")
    expected = ode.y.T[::-1].reshape(-1, 3, 3)
    np.testing.assert_allclose(lqr.terminal_riccati(a_mat, b_vec, t, TF_000), expected,
                               rtol=1e-7, atol=1e-12)
    gains = lqr.terminal_gain_schedule(a_mat, b_vec, t, TF_000)
    np.testing.assert_allclose(gains[-1], b_vec @ lqr.V_TERMINAL, rtol=1e-12)
    assert gains[-1][2] == pytest.approx(0.05 / 8.2, rel=1e-12)


def test_hamiltonian_exponential_definition(frozen):
    """(5.17)/(5.18) written out once by hand for t = 0."""
    a_mat, b_vec = frozen
    h = np.block([[a_mat, -np.outer(b_vec, b_vec)], [np.zeros((3, 3)), -a_mat.T]])
    fe = expm(-h * TF_000) @ np.vstack([np.eye(3), lqr.V_TERMINAL])
    np.testing.assert_allclose(lqr.terminal_riccati(a_mat, b_vec, [0.0], TF_000)[0],
                               fe[3:] @ np.linalg.inv(fe[:3]), rtol=1e-9)


def test_lqr_trackers_qualitative(nominal, frozen):
    """Extraction Sec. 8 item 13 on dh0 = -1 km: the infinite-horizon LQR (5.6) misses the exit
    altitude by order 1 % ([T] Sec. 5.1 "fails to reach the exit conditions"; Table 5.1's chosen
    row: -1.68 %); the terminal LQR (5.11) gets |%dh| << 1 % (Table 5.2: 6.83e-3 %) with a larger
    |u|max and a lower hmin than the nominal ([T] Sec. 5.2).

    Measured: infinite %dh = +0.55, terminal %dh = -2.4e-4, %dgamma = -0.79, |u|max 0.896 vs
    0.767 m/s^2, hmin 78.91 vs 79.26 km. Table values are not reproducible (no perturbation given).
    """
    x_nom, u_nom = nominal
    a_mat, b_vec = frozen
    dx0 = (-1e3, 0.0, 0.0)
    k_inf = lqr.infinite_horizon_gain(a_mat, b_vec)
    k_term = lqr.terminal_gain_schedule(a_mat, b_vec, T_GRID, TF_000)
    inf_err, *_ = _closed_loop(nominal, lambda i, s: lqr.feedback(k_inf, s, x_nom[:, i]), dx0=dx0)
    term_err, u_max, h_min, _effort = _closed_loop(
        nominal, lambda i, s: lqr.feedback(k_term[i], s, x_nom[:, i]), dx0=dx0)
    assert 0.1 < abs(_percent(inf_err)[0]) < 3.0
    assert abs(_percent(term_err)[0]) < 0.01
    assert u_max > np.max(np.abs(u_nom))
    assert h_min < x_nom[0].min()


def _predictive_and_terminal_effort(nominal, frozen, dh0):
    """int u^2 (m^2/s^3) of the predictive law and of the terminal LQR for entry h0 + dh0."""
    x_nom, _u = nominal
    k_term = lqr.terminal_gain_schedule(*frozen, T_GRID, TF_000)
    *_, effort = _closed_loop(nominal, lambda i, s: lqr.feedback(k_term[i], s, x_nom[:, i]),
                              dx0=(dh0, 0.0, 0.0))
    sol = solve_predictive((ENTRY_000[0] + dh0, ENTRY_000[1], ENTRY_000[2]))
    assert sol.converged
    return time_linear_integrals(sol.a, sol.b, sol.tf)[1], effort


def test_predictive_cheaper_than_terminal_lqr_high_entry(nominal, frozen):
    """Extraction Sec. 8 item 13 / Ch. 6 intro [T] (terminal LQR "magnitude of the total control
    effort involved is larger"): for dh0 = +1 km the predictive law, which meets all six BCs,
    costs int u^2 = 46.8 against 54.5 m^2/s^3 for the terminal LQR."""
    predictive, terminal = _predictive_and_terminal_effort(nominal, frozen, 1e3)
    assert predictive < terminal


@pytest.mark.xfail(strict=True, reason="dh0 = -1 km: predictive int u^2 75.1 > terminal LQR 66.5")
def test_predictive_cheaper_than_terminal_lqr_low_entry(nominal, frozen):
    """Same claim for dh0 = -1 km: NOT reproduced. The predictive law (tf' = 287.0 s, all six BCs
    met) costs 75.1 m^2/s^3, the terminal LQR (tf = 300 s, exit gamma 0.79 % and v 0.047 % off)
    66.5. Over dh0 = +-1, +-2 km, dv0 = +-20 m/s, dgamma0 = +-0.002 rad the predictive law is
    cheaper exactly for the entries that need less lift than nominal (higher, faster, shallower)
    and dearer for the others: it shortens tf' for those, and a shorter pass needs more lift."""
    predictive, terminal = _predictive_and_terminal_effort(nominal, frozen, -1e3)
    assert predictive < terminal


@pytest.mark.parametrize("k_factor, open_loop, closed_loop", [
    (0.8, (0.360e3, 9.86, 4.57e-4), (-0.155e3, 9.89, -1.30e-4)),
    (1.2, (-0.349e3, -10.0, -4.51e-4), (0.154e3, -9.75, 1.29e-4)),
])
def test_robust_law_constant_k_bias(nominal, k_factor, open_loop, closed_loop):
    """Ch. 7, (7.1)-(7.5) around the optimal nominal with K biased by k_factor: [V] Sec. 6.8
    exit errors (dh km, dv m/s, dgamma rad), reproduced within one unit of their last printed
    digit (1 m, 0.01 m/s, 1e-6 rad). Only one value is not reproduced to the rounding: K x 1.2
    robust dh = +153.46 m, which rounds to 0.153 km, where [V] prints 0.154. Extraction Sec. 10
    R8: |dh| and |dgamma| smaller than open loop; the speed error is not recovered."""
    x_nom, _u = nominal
    free, *_ = _closed_loop(nominal, lambda i, s: 0.0, k_factor)
    fed, *_ = _closed_loop(nominal, lambda i, s: robust.robust_delta_u(s, x_nom[:, i]), k_factor)
    for got, want in ((free, open_loop), (fed, closed_loop)):
        assert np.all(np.abs(got - np.array(want)) <= np.array([1.0, 0.01, 1e-6]))
    assert abs(fed[0]) < abs(free[0]) and abs(fed[2]) < abs(free[2])
    assert abs(fed[1]) > 0.9 * abs(free[1])


def test_robust_gains_literal():
    """(7.3)-(7.5): du = -(1.086957e-4 dr + 6.082725e-2 dv + 0.526 v_m dgamma), km-s, so one
    unit error of each state at v_m = 8.2 km/s gives 1.086957e-4 km/s^2 = 0.1086957 m/s^2,
    60.82725 m/s^2 and 4313.2 m/s^2 (negated)."""
    model = (90e3, 8200.0, -0.02)
    assert robust.robust_delta_u((91e3, 8200.0, -0.02), model) == pytest.approx(-0.1086957, rel=1e-12)
    assert robust.robust_delta_u((90e3, 9200.0, -0.02), model) == pytest.approx(-60.82725, rel=1e-12)
    assert robust.robust_delta_u((90e3, 8200.0, 0.98), model) == pytest.approx(-0.526 * 8.2e3, rel=1e-12)


def test_adaptive_law_is_algebraic_solution_of_pd_law():
    """(8.8) solves (8.6) with (8.5) substituted, eqs. (8.10)-(8.12): du = -eta Theta^T e -
    Psi Theta^T (A e + B du); (8.9) is eta Phi / (1 + Psi Theta^T B) e (B^T P e)."""
    x_d = km_state((85e3, 8190.0, -0.01))
    c = AotvConstants.km()
    a_mat, b_vec = jacobian_a(x_d, 0.6e-3, c), input_b(x_d)
    theta = adaptive.THETA0 * np.array([1.1, 0.9, 1.05])
    e = np.array([0.3, -2e-3, 1e-4])
    du = adaptive.adaptive_delta_u(theta, e, a_mat, b_vec)
    assert du == pytest.approx(-0.1 * theta @ e - 0.1 * theta @ (a_mat @ e + b_vec * du), rel=1e-12)
    rate = adaptive.theta_rate(theta, e, b_vec)
    expected = 0.1 / (1 + 0.1 * theta @ b_vec) * e * (b_vec @ adaptive.P_MATRIX @ e)
    np.testing.assert_allclose(rate, expected, rtol=1e-12)


@pytest.mark.parametrize("k_factor", [0.8, 1.2])
def test_adaptive_closed_loop_bounded_and_deterministic(nominal, k_factor):
    """Sec. 8.2 with the Sec. 8.2.2 constants, K biased +-20 %: [V] (extraction Sec. 8 item 17)
    the literal km-s implementation stays bounded over 300 s but Theta barely adapts (theta_h
    8.696e-3 -> 1.03e-2, theta_v and theta_gamma unchanged) and for K x 0.8 the exit altitude
    error is worse than open loop (-1.24 km vs +0.36 km). Reproduced: -1.238 km, theta_h
    1.026e-2 (K x 0.8); +1.174 km, 1.010e-2 (K x 1.2). So the thesis's Figs. 8.4-8.6 claim
    (errors settle near zero) is NOT reproduced by the printed constants; this test pins the
    literal behaviour and its determinism, as extraction Sec. 10 R9 recommends."""
    x_nom, u_nom = nominal

    def run():
        theta = adaptive.THETA0.copy()

        def law(i, state):
            nonlocal theta
            du, rate = adaptive.adaptive_step(theta, state, x_nom[:, i], u_nom[i])
            theta = theta + DT * rate
            return du

        return _closed_loop(nominal, law, k_factor)[0], theta

    error, theta = run()
    again, theta_again = run()
    np.testing.assert_array_equal(error, again)
    np.testing.assert_array_equal(theta, theta_again)
    assert np.all(np.isfinite(error)) and abs(error[0]) < 2e3
    if k_factor == 0.8:
        assert error[0] == pytest.approx(-1.24e3, abs=5.0)
        assert theta[0] == pytest.approx(1.03e-2, abs=5e-5)
    np.testing.assert_allclose(theta[1:], adaptive.THETA0[1:], rtol=1e-6)


def test_adaptive_model_matrix_eigenvalues_along_nominal(nominal):
    """Fig. 8.3 [T]: all eigenvalues of A_m (8.17) have negative real parts on [t0, tf]. [V]
    Sec. 6.10 (r_avg - R_e = 82.9 km): one real eigenvalue in [-2.2e-5, -7e-6] 1/s and a
    complex pair with real part in [-1.5e-5, -7e-6] 1/s and imaginary part +-0.00211-0.00213
    rad/s; for contrast A of (5.2) has a positive real eigenvalue (+0.0021 to +0.0041 1/s)."""
    x_nom, u_nom = nominal
    c = AotvConstants.km()
    xk = km_state(x_nom)
    r_avg = np.trapezoid(xk[0], T_GRID) / TF_000
    assert r_avg - c.r_earth == pytest.approx(82.9, abs=0.05)
    eig_m, eig_a = [], []
    for i in range(0, len(T_GRID), 10):
        eig_m.append(np.linalg.eigvals(adaptive_model_matrix(xk[:, i], u_nom[i] * 1e-3, r_avg, c)))
        eig_a.append(np.linalg.eigvals(jacobian_a(xk[:, i], u_nom[i] * 1e-3, c)))
    eig_m, eig_a = np.array(eig_m), np.array(eig_a)
    assert np.all(eig_m.real < 0)
    real = eig_m[eig_m.imag == 0].real
    pair = eig_m[eig_m.imag != 0]
    assert real.min() == pytest.approx(-2.2e-5, abs=5e-7) and real.max() == pytest.approx(-7e-6, abs=5e-7)
    assert pair.real.min() == pytest.approx(-1.5e-5, abs=5e-7)
    assert pair.real.max() == pytest.approx(-7e-6, abs=5e-7)
    assert np.abs(pair.imag).min() == pytest.approx(0.00211, abs=5e-6)
    assert np.abs(pair.imag).max() == pytest.approx(0.00213, abs=5e-6)
    largest = eig_a.real.max(axis=1)
    assert largest.min() == pytest.approx(0.0021, abs=5e-5)
    assert largest.max() == pytest.approx(0.0041, abs=5e-5)
