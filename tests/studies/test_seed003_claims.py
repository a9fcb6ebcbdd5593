"""Seed 003 tier B (printed claims needing two runs or the reconstructed trajectory) and tier C
(inferred 150,000 ft values). Single-run claims are expectations in scenarios/shuttle_*.json."""

import math

import numpy as np
import pytest

from aotv_cosim.guidance import shuttle_lqr as lqr
from aotv_cosim.physics import shuttle_trajectory as st
from aotv_cosim.physics.shuttle_pitch import FT
from aotv_cosim.output.runner import run_scenario
from aotv_cosim.simulation.loading import load_scenario

from tests.helpers import SCENARIOS

X0 = (math.radians(5.0), 0.0)


def run(tmp_path, name):
    """Run scenarios/shuttle_<name>.json; its summary."""
    summary = run_scenario(load_scenario(SCENARIOS / f"shuttle_{name}.json"),
                           tmp_path / name, make_plots=False).as_json()
    assert summary["status"] == "completed"
    return summary


@pytest.fixture(scope="module")
def nominal():
    return st.fly()


@pytest.fixture(scope="module")
def window_150(nominal):
    """The LQR FMU's a priori data at 150,000 ft: coefficients over the 446.8-length window."""
    i = st.start_indices(nominal)["150kft"]
    return st.coefficient_model(st.predict(nominal.h[i], nominal.v[i], nominal.gamma[i], 446.8))


@pytest.mark.integration
def test_optimal_torque_ratio_above_1e3(tmp_path):
    """Sec. 4.2: the optimal elevator torque at 150 kft exceeds that at 400 kft by > 3 orders."""
    low, high = run(tmp_path, "lqr_150kft"), run(tmp_path, "lqr_400kft")
    torque = [max(abs(s["min"]["pitch.torque"]["value"]), abs(s["max"]["pitch.torque"]["value"]))
              for s in (low, high)]
    assert torque[0] / torque[1] > 1e3


def test_asymptotic_within_02_deg_of_numerical_lqr(window_150, nominal):
    """Sec. 4.3.4: asymptotic vs numerical LQR at 150 kft within 0.2 deg and 0.2 deg/s (the
    frozen-coefficient variant the ShuttleLqr FMU uses by default)."""
    num = lqr.NumericalLqr.solve(window_150, 446.8, 6.55e6, X0)
    asym = lqr.AsymptoticLqr.at_final(window_150, 446.8, 6.55e6, "reduced", frozen=True)
    _, xs = asym.trajectory(X0, num.xi)
    err = np.abs(xs - num.x).max(axis=0)
    v = nominal.v[st.start_indices(nominal)["150kft"]]
    assert math.degrees(err[0]) < 0.2
    assert math.degrees(err[1]) * v / st.GENERIC.L < 0.2


@pytest.mark.xfail(strict=True, reason="Literal (4.86) with roots of the full quartic (4.82) and "
                   "A(xi) following the coefficients: the C_ijk frozen at xi_f and K = -[A^T + "
                   "Lambda' Lambda^-1] cancel to 1e-5, and on the reconstructed glide omega0 "
                   "drifts 4.6% and omega1' = 1.9e-7 (the thesis's fit implies 7e-8) over the "
                   "window: max error 3.9 deg (docs/seed003.md)")
def test_literal_asymptotic_within_02_deg(window_150):
    num = lqr.NumericalLqr.solve(window_150, 446.8, 6.55e6, X0)
    _, xs = lqr.AsymptoticLqr.at_final(window_150, 446.8, 6.55e6).trajectory(X0, num.xi)
    assert math.degrees(np.abs(xs - num.x).max(axis=0)[0]) < 0.2


@pytest.mark.integration
@pytest.mark.xfail(strict=True, reason="Die-out at 150 kft is 76 s (to 0.05 deg) against 'about "
                   "120 s' +-30%: with the tier-C omega1 = 1.77e-3 and V = 6000 ft/s even frozen "
                   "coefficients die out in 93 s, and the reconstructed glide descends at "
                   "-1.25 deg (inferred -0.5 deg), so damping grows faster (docs/seed003.md)")
def test_feedforward_die_out_150kft(tmp_path):
    s = run(tmp_path, "feedforward_150kft")
    assert 0.7 * 120 <= s["final"]["pitch.settle_time"] <= 1.3 * 120


@pytest.mark.integration
@pytest.mark.xfail(strict=True, reason="Adaptive control time at 400 kft is 2.7 min against "
                   "'about 4 min' (Sec. 5.1.1) / '4-5 min' (Conclusions) with lambda = 1.11e-3 and "
                   "the printed Gamma; the command peaks at 26.2 deg and saturates for 9 s "
                   "(docs/seed003.md)")
def test_adaptive_control_time_400kft(tmp_path):
    s = run(tmp_path, "adaptive_400kft")
    assert 240 <= s["final"]["pitch.settle_time"] <= 300


def test_tier_c_150kft_point(nominal):
    """Extraction 4.2 / 6.4 [INFERRED] at 150 kft: omega0, omega1 (calibrated, so exact here),
    mu about 6.25e-5 (+-10%), V 6000-8000 ft/s. gamma about -0.5 deg is NOT reproduced
    (-1.25 deg): reported in docs/seed003.md, not asserted."""
    i = st.start_indices(nominal)["150kft"]
    c = nominal.coefficients()
    assert c["omega0"][i] == pytest.approx(5.596e-5, rel=1e-3)
    assert c["omega1"][i] == pytest.approx(1.7698e-3, rel=1e-3)
    assert c["mu"][i] == pytest.approx(6.25e-5, rel=0.1)
    assert 6000 * 0.99 <= nominal.v[i] / FT <= 8000
