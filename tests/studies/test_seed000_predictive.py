"""Seed 000 predictive time-linear control (Ch. 6) and predictive adaptation to K (Sec. 8.1):
direct (a, b, tf') shooting, the thesis iteration (6.3)/(6.4), Table 8.1, (8.1)-(8.4).

Expected values: extraction = `shared/research/seed-000-aotv-thesis.md`; [T] thesis, [D] derived
by hand, [V] the extraction author's independent prototype (evidence, not gospel).
"""

import numpy as np
import pytest

from aotv_cosim.guidance.optimal_bvp import solve_min_effort
from aotv_cosim.guidance.predictive import (
    TF_INTERCEPT_CORRECTED, TF_INTERCEPT_PRINTED, estimate_k_ball, fly_time_linear,
    solve_predictive, solve_predictive_adaptive, solve_predictive_thesis, table_8_1_fit,
)
from aotv_cosim.guidance.time_linear import time_linear_integrals
from aotv_cosim.physics.planar import ENTRY_000, EXIT_000, K_BALL_000, AotvConstants, dynamics

# Table 8.1 verbatim: K (1/m), a (m/s^2), b (m/s^3), tf (s), int |u| dt (km/s).
TABLE_8_1 = [
    (0.0002336, 0.633419201, -0.002032061, 332.2244687, 0.099148864),
    (0.00024, 0.650203935, -0.002105412, 327.9266633, 0.100782653),
    (0.00025, 0.672450161, -0.002173017, 322.6315003, 0.104234172),
    (0.00026, 0.700237749, -0.002317169, 315.7716585, 0.106015604),
    (0.00027, 0.719831922, -0.002358413, 311.6257794, 0.109901126),
    (0.000292, 0.769349796, -0.002546601, 300.9622284, 0.116211703),
    (0.0003, 0.789657293, -0.002651214, 296.6114613, 0.117596641),
    (0.00031, 0.813292134, -0.00276172, 291.7738226, 0.119741458),
    (0.00032, 0.832813066, -0.002818261, 288.1658147, 0.122973347),
    (0.00033, 0.855070656, -0.002916361, 283.9241124, 0.12522635),
    (0.000335, 0.868977731, -0.003006461, 281.1239682, 0.125488569),
]

# Perturbed entries (h0 m, v0 m/s, gamma0 rad) within the ranges of extraction Sec. 6.7 [V].
PERTURBED = [
    (91e3, 8200.0, -0.02), (88e3, 8200.0, -0.02), (92e3, 8200.0, -0.02),
    (90e3, 8180.0, -0.02), (90e3, 8250.0, -0.02),
    (90e3, 8200.0, -0.018), (90e3, 8200.0, -0.022),
]


def _exit_error(entry, sol, k_ball=K_BALL_000):
    _t, h, v, gamma = fly_time_linear(entry, sol.a, sol.b, sol.tf, k_ball)
    return h[-1] - EXIT_000[0], v[-1] - EXIT_000[1], gamma[-1] - EXIT_000[2]


def test_nominal_entry_solution():
    """[V] Sec. 6.7: nominal entry gives a = 0.77166 m/s^2, b = -2.578097e-3 m/s^3, tf' =
    300.317 s, int u^2 = 59.4098 m^2/s^3, hmin = 79.276 km; all six BCs met (Ch. 6)."""
    sol = solve_predictive(ENTRY_000)
    assert sol.converged
    assert sol.a == pytest.approx(0.77166, abs=5e-6)
    assert sol.b == pytest.approx(-2.578097e-3, abs=5e-10)
    assert sol.tf == pytest.approx(300.317, abs=5e-4)
    assert time_linear_integrals(sol.a, sol.b, sol.tf)[1] == pytest.approx(59.4098, abs=5e-5)
    dh, dv, dgamma = _exit_error(ENTRY_000, sol)
    assert abs(dh) < 0.05 and abs(dv) < 1e-4 and abs(dgamma) < 1e-8
    _t, h, _v, _g = fly_time_linear(ENTRY_000, sol.a, sol.b, sol.tf,
                                    t_eval=np.linspace(0.0, sol.tf, 3001))
    assert h.min() == pytest.approx(79.276e3, abs=0.5)


@pytest.mark.parametrize("row", TABLE_8_1, ids=[f"K={r[0]}" for r in TABLE_8_1])
def test_table_8_1_row(row):
    """Table 8.1, nominal entry, K varied. Tolerances of extraction Sec. 6.9: a within 1 %, b
    within 2.5 %, tf within 1.5 s, int |u| dt within 1 %. [V] maxima 0.45 %, 1.8 %, 0.95 s,
    0.71 %; the thesis's own rows miss the exit by up to 0.17 km (loosely converged)."""
    k, a, b, tf, abs_u_km = row
    sol = solve_predictive(ENTRY_000, k_ball=k)
    assert sol.converged
    assert sol.a == pytest.approx(a, rel=0.01)
    assert sol.b == pytest.approx(b, rel=0.025)
    assert sol.tf == pytest.approx(tf, abs=1.5)
    assert time_linear_integrals(sol.a, sol.b, sol.tf)[0] / 1e3 == pytest.approx(abs_u_km, rel=0.01)
    dh, dv, dgamma = _exit_error(ENTRY_000, sol, k)
    assert abs(dh) < 0.05 and abs(dv) < 1e-4 and abs(dgamma) < 1e-8


def test_table_8_1_deviations_match_prototype():
    """[V] Sec. 6.9: largest deviations from Table 8.1 are a 0.45 %, b 1.8 %, tf 0.95 s, int |u|
    0.71 %. Reproduced to those digits except int |u|: 0.72 % here (row K = 0.00025 1/m), which
    is also what the [V] row itself gives (0.103483 vs 0.104234 km/s is 0.720 %), so the "0.71"
    summary is the prototype's rounding slip. Measured: 0.454 %, 1.787 %, 0.952 s, 0.721 %."""
    dev = []
    for k, a, b, tf, abs_u_km in TABLE_8_1:
        sol = solve_predictive(ENTRY_000, k_ball=k)
        abs_u = time_linear_integrals(sol.a, sol.b, sol.tf)[0] / 1e3
        dev.append((abs(sol.a / a - 1), abs(sol.b / b - 1), abs(sol.tf - tf), abs(abs_u / abs_u_km - 1)))
    worst_a, worst_b, worst_tf, worst_u = np.max(dev, axis=0)
    assert worst_a == pytest.approx(0.0045, abs=5e-5)
    assert worst_b == pytest.approx(0.018, abs=5e-4)
    assert worst_tf == pytest.approx(0.95, abs=5e-3)
    assert worst_u == pytest.approx(0.0072, abs=5e-5)


@pytest.mark.parametrize("entry", PERTURBED, ids=[str(e) for e in PERTURBED])
def test_time_linear_is_near_optimal_at_same_final_time(entry):
    """Ch. 6 [T]: the optimal u oscillates about the time-linear u and the costs are about the
    same. Extraction Sec. 10 R6: int u^2 of the predictive law within 0.1 % of the optimum of the
    2PBVP (3.21) with the same six BCs and tf' ([V] within 0.01 % for these ranges); the optimum
    cannot be larger than the time-linear cost. Measured here: at most 3.2e-5 relative."""
    sol = solve_predictive(entry)
    assert sol.converged
    optimum = solve_min_effort(entry, EXIT_000, sol.tf, guess=(sol.a, sol.b))
    assert optimum.success, optimum.message
    linear = time_linear_integrals(sol.a, sol.b, sol.tf)[1]
    assert optimum.effort() <= linear
    assert linear / optimum.effort() - 1.0 < 1e-3
    dh, dv, dgamma = _exit_error(entry, sol)
    assert abs(dh) < 0.05 and abs(dv) < 1e-4 and abs(dgamma) < 1e-8


@pytest.mark.xfail(strict=True, reason="v0 + 0.1 km/s: time-linear cost 0.115 % above optimum")
def test_time_linear_near_optimal_fast_entry():
    """Extraction Sec. 6.7 [V] claims the 0.01 % agreement up to v0 + 0.1 km/s. Not reproduced:
    at (90 km, 8.3 km/s, -0.02 rad) the shooting converges to a = 0.003435 m/s^2, b =
    -3.2706e-4 m/s^3, tf' = 457.829 s, exit met to 1e-8, and int u^2 = 3.19153 m^2/s^3 against
    3.18786 for the 2PBVP optimum at that tf' (tol 1e-6 and 1e-8 agree to 1e-9): 0.115 % above,
    outside the 0.1 % criterion. With u almost zero on average, the cost is small and the optimal
    law's curvature is no longer negligible against it."""
    entry = (90e3, 8300.0, -0.02)
    sol = solve_predictive(entry)
    optimum = solve_min_effort(entry, EXIT_000, sol.tf, guess=(sol.a, sol.b))
    assert time_linear_integrals(sol.a, sol.b, sol.tf)[1] / optimum.effort() - 1.0 < 1e-3


def test_trends_with_entry_perturbations():
    """Figs. 6.4-6.6 trends ([V], extraction Sec. 10 R6): a decreases and tf' increases as h0,
    v0 or gamma0 increases, the other entry values held at Table 4.1."""
    for series in ([(88e3, 8200.0, -0.02), ENTRY_000, (91e3, 8200.0, -0.02), (92e3, 8200.0, -0.02)],
                   [(90e3, 8180.0, -0.02), ENTRY_000, (90e3, 8250.0, -0.02)],
                   [(90e3, 8200.0, -0.022), ENTRY_000, (90e3, 8200.0, -0.018)]):
        sols = [solve_predictive(e) for e in series]
        assert all(s.converged for s in sols)
        assert np.all(np.diff([s.a for s in sols]) < 0)
        assert np.all(np.diff([s.tf for s in sols]) > 0)


def test_thesis_iteration_does_not_converge():
    """Extraction Sec. 8 item 12 [V]: the printed update (6.3) with slope (6.4) oscillates in a
    4-cycle between about 279 and 325 s for h0 = 91 km and does not converge. Reproduced: tf'
    goes 300, 324.6, 279.0, 319.3, 300.4, 324.5, 279.5, 319.5 s and the exit gamma miss stays
    above 1e-3 rad."""
    history = solve_predictive_thesis((91e3, 8200.0, -0.02), n_updates=8)
    tfs = np.array([h[2] for h in history])
    misses = np.array([h[3] for h in history])
    assert tfs[1:].min() == pytest.approx(279.0, abs=1.0)
    assert tfs[1:].max() == pytest.approx(325.0, abs=1.0)
    np.testing.assert_allclose(tfs[5:8], tfs[1:4], atol=1.0)
    assert np.all(np.abs(misses) > 1e-3)


def test_k_estimate_recovers_plant_k():
    """Eq. (8.1): K from the measured entry deceleration of the plant (2.7) equals the plant's K,
    for the nominal and the +-20 % values (Sec. 8.1, Ch. 7)."""
    h0, v0, gamma0 = ENTRY_000
    for k in (0.8 * K_BALL_000, K_BALL_000, 1.2 * K_BALL_000):
        c = AotvConstants.si(k)
        v_dot = dynamics(np.array([c.r_earth + h0, v0, gamma0]), 0.77, c)[1]
        assert estimate_k_ball(v_dot, h0, v0, gamma0) == pytest.approx(k, rel=1e-12)


def test_fits_8_2_to_8_4_verbatim():
    """(8.2)-(8.4) with K in 1/km (extraction Sec. 8 item 2): at K = 0.292/km a = 2.32306 * 0.292
    + 0.090752 = 0.7691 m/s^2 (Table 8.1: 0.769350); with K in 1/m a would be 0.0908, not the
    table. (8.2) passes through the first and last rows of Table 8.1 [D], to the 1e-6 m/s^2 that
    its printed coefficients resolve."""
    a, b, tf = table_8_1_fit(2.92e-4)
    assert a == pytest.approx(2.32306 * 0.292 + 0.090752, rel=1e-12)
    assert b == pytest.approx((-8.99571 * 0.292 + 0.0623299) * 1e-3, rel=1e-12)
    assert tf == pytest.approx(-503.94971 * 0.292 + 448.94712, rel=1e-12)
    assert a == pytest.approx(0.7691, abs=5e-5)
    for k, a_tab, _b, _tf, _u in (TABLE_8_1[0], TABLE_8_1[-1]):
        assert table_8_1_fit(k)[0] == pytest.approx(a_tab, abs=1e-6)


def test_fit_8_4_intercept_typo():
    """Extraction Sec. 8 item 3 [D]: the line through the first and last Table 8.1 rows has slope
    -503.9497 and intercept 449.94712 s; the printed (8.4) intercept 448.94712 is 1.000 s low at
    both end points (331.224 vs 332.224; 280.124 vs 281.124)."""
    assert pytest.approx(1.0, abs=1e-12) == TF_INTERCEPT_CORRECTED - TF_INTERCEPT_PRINTED
    for k, _a, _b, tf_tab, _u in (TABLE_8_1[0], TABLE_8_1[-1]):
        assert table_8_1_fit(k, corrected_intercept=True)[2] == pytest.approx(tf_tab, abs=1e-3)
        assert table_8_1_fit(k)[2] == pytest.approx(tf_tab - 1.0, abs=1e-3)
    k0, k1 = TABLE_8_1[0][0] * 1e3, TABLE_8_1[-1][0] * 1e3
    slope = (TABLE_8_1[-1][3] - TABLE_8_1[0][3]) / (k1 - k0)
    assert slope == pytest.approx(-503.9497, abs=1e-3)


def test_fit_8_3_is_an_approximate_line():
    """Extraction Sec. 8 item 3: (8.3) is neither the end-point line (slope -9.6095e-3) nor the
    least-squares line (-9.276e-3) of Table 8.1; it stays within the 2.5 % b tolerance of every
    row (worst 1.8 % at K = 0.000335 1/m)."""
    ks = np.array([r[0] for r in TABLE_8_1]) * 1e3
    bs = np.array([r[2] for r in TABLE_8_1])
    assert (bs[-1] - bs[0]) / (ks[-1] - ks[0]) * 1e3 == pytest.approx(-9.6095, abs=1e-3)
    assert np.polyfit(ks, bs, 1)[0] * 1e3 == pytest.approx(-9.276, abs=1e-3)
    fitted = np.array([table_8_1_fit(r[0])[1] for r in TABLE_8_1])
    assert np.max(np.abs(fitted / bs - 1)) == pytest.approx(0.018, abs=1e-3)



@pytest.mark.parametrize("factor", [0.8, 1.2])
def test_predictive_adaptive_estimates_k_and_resolves(factor):
    """Sec. 8.1: from the drag measured at entry, (8.1) recovers the plant's K and the law is the
    predictive solution for that K; K x 0.8 is Table 8.1 row 1 (a 0.633419, tf 332.22 s, within
    the Sec. 6.9 tolerances 1 % and 1.5 s)."""
    k = factor * K_BALL_000
    h0, v0, _gamma0 = ENTRY_000
    c = AotvConstants.si(k)
    drag = k * np.exp(-h0 / c.scale_height) * v0 ** 2
    k_est, sol = solve_predictive_adaptive(ENTRY_000, drag)
    assert k_est == pytest.approx(k, rel=1e-12)
    direct = solve_predictive(ENTRY_000, k_ball=k)
    assert sol.converged and (sol.a, sol.b, sol.tf) == pytest.approx((direct.a, direct.b, direct.tf), rel=1e-9)
    if factor == 0.8:
        assert sol.a == pytest.approx(TABLE_8_1[0][1], rel=0.01)
        assert sol.tf == pytest.approx(TABLE_8_1[0][3], abs=1.5)
