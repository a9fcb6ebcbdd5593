"""The vehicle FMUs (PointMassVehicle, LiftBankVehicle, AlphaBankVehicle) against the physics.

Each FMU is run with constant inputs in fmpy.simulate_fmu and compared with the same RK4 of
`physics.point_mass` driven by the polar the FMU documents: the adapters add nothing of their own.
"""

import math

import numpy as np
import pytest
from fmpy import simulate_fmu

from aotv_cosim.fmu import build as fmu_build
from aotv_cosim.physics import mrrv, orbit, point_mass, sx2

pytestmark = pytest.mark.integration

RHO = 2.0e-4
SIGMA = 0.3


def _fly(name, inputs, stop=20.0, step=0.5):
    """Final row of the FMU flown with constant inputs (zero-order hold) to `stop` s."""
    result = simulate_fmu(fmu_build.ensure_fmu(name), stop_time=stop, step_size=step,
                          output_interval=step, start_values=inputs,
                          output=["h", "theta", "phi", "v", "gamma", "psi", "apogee_alt",
                                  "dv_circ", "inclination", "drag_acc", "lift_acc"])
    return result[-1]


def _expected(h0, v0, gamma0, r_e, cl_s_m, cd_s_m, lift_acc=0.0, gravity=1, stop=20.0, step=0.5):
    x = [r_e + h0, 0.0, 0.0, v0, gamma0, 0.0]
    args = (RHO, lift_acc, cl_s_m, cd_s_m, SIGMA, gravity, 9.81, orbit.MU_EARTH)
    for _ in range(round(stop / step)):
        x = point_mass.integrate(x, step, 0.5, args)
    return x


def _assert_state(row, x, r_e):
    got = [row["h"] + r_e, row["theta"], row["phi"], row["v"], row["gamma"], row["psi"]]
    np.testing.assert_allclose(got, x, rtol=1e-12, atol=1e-12)


def test_lift_bank_vehicle_uses_the_parabolic_polar():
    """Seed 001 eqs. (3.9)-(3.10): C_L = C_L* lambda, C_D = C_D* (1 + lambda^2)/2."""
    lam = 0.7
    row = _fly("LiftBankVehicle", {"rho": RHO, "sigma": SIGMA, "lam": lam})
    cl_s_m, cd_s_m = mrrv.coefficients_per_mass(lam)
    x = _expected(60e3, 7851.0, math.radians(-1.35), mrrv.R_EARTH, cl_s_m, cd_s_m)
    _assert_state(row, x, mrrv.R_EARTH)
    assert row["drag_acc"] == pytest.approx(0.5 * RHO * x[3] ** 2 * cd_s_m, rel=1e-12)
    assert row["inclination"] == pytest.approx(orbit.inclination(x[2], x[5]), abs=1e-14)


def test_alpha_bank_vehicle_uses_the_sx2_polar():
    """Seed 002 simulation section: C_L = 2.5457 a - 0.0448, C_D = 3.7677 a^2 - 0.1427 a + 0.1971."""
    alpha = math.radians(15.0)
    row = _fly("AlphaBankVehicle", {"rho": RHO, "sigma": SIGMA, "alpha": alpha})
    s_m = sx2.S_REF / sx2.MASS
    cl = 2.5457 * alpha - 0.0448
    cd = 3.7677 * alpha ** 2 - 0.1427 * alpha + 0.1971
    x = _expected(60960.0, 5181.6, 0.0, sx2.R_EARTH, cl * s_m, cd * s_m)
    _assert_state(row, x, sx2.R_EARTH)
    assert row["lift_acc"] == pytest.approx(0.5 * RHO * x[3] ** 2 * cl * s_m, rel=1e-12)


def test_point_mass_vehicle_reports_the_exit_orbit():
    """Seed 000 extraction Sec. 7: apogee altitude and circularization dv from the current state."""
    row = _fly("PointMassVehicle", {"rho": 0.0, "sigma": 0.0, "u_lift": 0.0, "gamma0": 0.01})
    h, v, gamma = row["h"], row["v"], row["gamma"]
    apogee = orbit.apsis_altitudes(h, v, gamma)[1]
    assert row["apogee_alt"] == pytest.approx(apogee, rel=1e-12)
    assert row["dv_circ"] == pytest.approx(orbit.circularization_delta_v(h, v, gamma), rel=1e-12)
    assert row["apogee_alt"] > h and row["dv_circ"] > 0.0


def test_trim_bank_vehicle_adds_radiative_heating():
    """qdot_total = qdot (Sutton-Graves) + qdot_rad (Tauber-Sutton) at 10.3 km/s; heat_load_total the
    same trapezoid over qdot_total as heat_load over qdot (density held)."""
    from aotv_cosim.physics import aero

    rho, v0, rn = 1.0e-4, 10300.0, 2.0
    result = simulate_fmu(fmu_build.ensure_fmu("TrimBankVehicle"), stop_time=2.0, step_size=0.5,
                          output_interval=0.5, start_values={"rho": rho, "v0": v0, "nose_radius": rn},
                          output=["v", "qdot", "qdot_rad", "qdot_total", "heat_load", "heat_load_total"])
    q_rad = [aero.radiative_heating_rate(rho, v, rn) for v in result["v"]]
    np.testing.assert_allclose(result["qdot_rad"], q_rad, rtol=1e-12)
    np.testing.assert_allclose(result["qdot_total"], result["qdot"] + result["qdot_rad"], rtol=1e-12)
    q_total = result["qdot_total"]
    expected = np.concatenate([[0.0], np.cumsum(0.25 * (q_total[:-1] + q_total[1:]))])
    np.testing.assert_allclose(result["heat_load_total"], expected, rtol=1e-12)
    assert np.all(result["heat_load_total"][1:] > result["heat_load"][1:])
