"""The FMUs' per-call shortcuts give what the plain computation gives, to the bit.

- `AotvSlave.get_real`/`set_real` read and write one value without a loop: the same values as
  the general path.
- Values cached once per `revision` (the vehicle's heating rate, the pitch vehicle's coefficients,
  the entry-tracking law's outputs) follow every set and every step: each equals the physics or
  guidance function evaluated afresh on the FMU's current state and inputs.

The slave classes run in this process (`source_check.fmu_class`), without an FMU archive.
"""

import math

import pytest

from aotv_cosim.fmu import build as fmu_build
from aotv_cosim.fmu import source_check
from aotv_cosim.physics import aero
from aotv_cosim.physics import shuttle_pitch as sp

pytestmark = pytest.mark.integration  # builds and runs the package's FMUs


def slave(name: str):
    """A fresh instance of the FMU class of fmus_src/<name>.py, initialized at t = 0."""
    cls = source_check.fmu_class(fmu_build.fmus_src_dir() / f"{name}.py")
    instance = cls(instance_name=name, resources=".")
    instance.setup_experiment(0.0, 300.0, None)
    instance.enter_initialization_mode()
    instance.exit_initialization_mode()
    return instance


def vrs(instance, *names):
    by_name = {var.name: vr for vr, var in instance.vars.items()}
    return [by_name[n] for n in names]


def outputs(instance) -> list:
    return [vr for vr, var in instance.vars.items() if var.causality.name == "output"]


def test_one_value_gets_and_sets_as_many_do():
    one, many = slave("PointMassVehicle"), slave("PointMassVehicle")
    rho, u = vrs(one, "rho", "u_lift")
    one.set_real([rho], [3.0e-6])
    one.set_real([u], [0.4])
    many.set_real([rho, u], [3.0e-6, 0.4])
    assert (one.rho, one.u_lift) == (many.rho, many.u_lift) == (3.0e-6, 0.4)
    for instance in (one, many):
        assert instance.do_step(0.0, 0.1)
    every = outputs(many)
    assert [one.get_real([vr])[0] for vr in every] == many.get_real(every)


def test_vehicle_heating_follows_density_and_state():
    vehicle = slave("PointMassVehicle")
    rho, qdot = vrs(vehicle, "rho", "qdot")

    def fresh():
        return aero.stagnation_heating_rate(vehicle.rho, vehicle.x[3], vehicle.k_q, vehicle.q_rho_exp,
                                            vehicle.q_v_exp, vehicle.nose_radius)

    heat_load = 0.0
    for k, density in enumerate((3.0e-6, 3.3e-6, 3.3e-6, 2.9e-6)):
        vehicle.set_real([rho], [density])
        assert vehicle.get_real([qdot]) == [fresh()]  # the density just set, the state before the step
        q_start = fresh()
        assert vehicle.do_step(k * 0.1, 0.1)
        assert vehicle.get_real([qdot]) == [fresh()]  # the state after the step
        heat_load += 0.5 * 0.1 * (q_start + fresh())
        assert vehicle.heat_load == heat_load


def test_pitch_coefficients_follow_inputs_and_rate_history():
    pitch = slave("PitchVehicle")
    names = ("omega0", "omega1", "f", "mu", "torque")
    read = vrs(pitch, *names)
    h, v, delta_e = vrs(pitch, "h", "v", "delta_e")

    def fresh():
        planet = sp.Planet(pitch.R_e, pitch.g_s, sp.PLANET.rho_s, pitch.scale_height)
        c = sp.coefficients(pitch.rho, pitch.h, pitch.v, pitch.gamma, pitch.alpha0, pitch.rates.rates(),
                            pitch._aero(), planet)
        return [c.omega0, c.omega1, c.f, c.mu, sp.elevator_torque(c.mu, pitch.delta_e, pitch.v)]

    for k in range(5):  # samples 1 s apart: the rate history changes at every step
        pitch.set_real([h, v, delta_e], [pitch.h - 500.0, pitch.v - 2.0, 0.01 * k])
        assert pitch.get_real(read) == fresh()
        assert pitch.do_step(float(k), 1.0)
        assert pitch.get_real(read) == fresh()
    assert len(pitch.rates.samples) == 3


@pytest.mark.parametrize("moved", ["r", "v", "phi"])
def test_entry_tracking_outputs_follow_every_set(moved):
    law = slave("EntryTrackingGuidance")
    every = outputs(law)
    (vr,) = vrs(law, moved)
    start = law.get_real(every)
    value = getattr(law, moved)
    law.set_real([vr], [value * (1.0 + 1e-4) if value else 1e-4])
    changed = law.get_real(every)
    assert changed != start
    again = slave("EntryTrackingGuidance")  # the same inputs in a new instance: the same outputs
    again.set_real([vr], [getattr(law, moved)])
    assert again.get_real(every) == changed
    law.set_real([vr], [value])
    assert law.get_real(every) == start
    assert all(map(math.isfinite, start))
