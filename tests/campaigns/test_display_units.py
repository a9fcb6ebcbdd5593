"""Display units of plots and console tables (`output.display_units.display`); files keep SI."""

from aotv_cosim.output.display_units import display


def test_load_factors_show_in_g_and_counts_of_runs_above_a_limit_do_not():
    assert display("peak_load_factor_p50", "1") == ("g", 1.0)
    assert display("max.vehicle.load_factor", "1") == ("g", 1.0)
    assert display("over_load_factor", "1") == ("1", 1.0)


def test_heat_rates_show_in_w_per_cm2_and_vehicle_speeds_in_km_per_s():
    assert display("peak_heat_rate_p50", "W/m2") == ("W/cm2", 1e-4)
    assert display("exit.vehicle.v", "m/s") == ("km/s", 1e-3)
    assert display("dv_total_p50", "m/s") == ("m/s", 1.0)


def test_angles_show_in_degrees_and_altitudes_in_km():
    import math

    assert display("exit.vehicle.gamma", "rad") == ("deg", 180.0 / math.pi)
    assert display("actuator.rate", "rad/s") == ("deg/s", 180.0 / math.pi)
    assert display("vehicle.h", "m") == ("km", 1e-3)
    assert display("vehicle.heat_load", "J/m2") == ("kJ/cm2", 1e-7)
