"""Entry corridor of the bank-modulated aerocapture vehicles: full lift up / full lift down.

For each configuration of `physics.aerocapture_vehicles`, bisection on the entry flight-path
angle gamma0 (interface 122 km, GEO-return speed) of the exit apogee miss predicted by the
bank-angle NPC's own model (`guidance.npc_bank.predict`, US76 density, RK4 step 1 s): the
steepest gamma0 that still reaches the target apogee flying full lift up (sigma = 0), the
shallowest flying full lift down (sigma = pi), and the gamma0 whose pass meets the target at
sigma = 90 deg (no vertical lift, the centre of the control authority). Corridor width =
shallow - steep. Run: `python -m aotv_cosim.studies.aerocapture_corridor`.
"""

import math

from aotv_cosim.guidance import npc_bank
from aotv_cosim.physics import aerocapture_vehicles as av


def model_of(vehicle: av.TrimVehicle) -> npc_bank.BankModel:
    """The predictor model of a vehicle (US76, inverse-square gravity)."""
    return npc_bank.BankModel(vehicle.cl * vehicle.s_ref / vehicle.mass, vehicle.cd * vehicle.s_ref / vehicle.mass)


def boundary(vehicle: av.TrimVehicle, x: float, steep: float = math.radians(-30.0),
             shallow: float = math.radians(-2.0), iterations: int = 40) -> float:
    """gamma0 (rad) at which the pass flown at vertical lift fraction x = cos sigma exits on the
    target apogee: bisection between a steep bound (captured too low or no exit) and a shallow one
    (apogee above the target)."""
    model = model_of(vehicle)
    settings = npc_bank.BankSettings(av.TARGET_APOGEE, av.H_INTERFACE, step=1.0)
    v0 = av.geo_return_speed()

    def too_shallow(gamma0):
        p = npc_bank.predict(0.0, (av.H_INTERFACE, v0, gamma0), x, 1.0, model, settings)
        return p.exited and p.miss > 0.0

    if too_shallow(steep):
        return math.nan  # the steep bound still skips out: the corridor is wider than searched
    for _ in range(iterations):
        mid = 0.5 * (steep + shallow)
        if too_shallow(mid):
            shallow = mid
        else:
            steep = mid
    return 0.5 * (steep + shallow)


def corridor(vehicle: av.TrimVehicle) -> dict:
    """{"lift_up", "lift_down", "no_vertical_lift", "width"}: gamma0 bounds in deg."""
    up, down, mid = (math.degrees(boundary(vehicle, x)) for x in (1.0, -1.0, 0.0))
    return {"lift_up": up, "lift_down": down, "no_vertical_lift": mid, "width": down - up}


if __name__ == "__main__":
    for v in (av.AFE, av.AOTV):
        c = corridor(v)
        print(f"{v.name}: L/D {v.lift_to_drag:.2f}, beta {v.ballistic_coefficient:.1f} kg/m2: "
              f"full lift up {c['lift_up']:.3f} deg, full lift down {c['lift_down']:.3f} deg, "
              f"width {c['width']:.3f} deg; sigma = 90 deg at {c['no_vertical_lift']:.3f} deg")
