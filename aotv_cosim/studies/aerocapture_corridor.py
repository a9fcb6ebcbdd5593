"""Entry corridors of the two aerocapture vehicles (`physics.aerocapture_vehicles`): full lift up,
full lift down and no vertical lift.

Flown by the corridor command's own code (`studies.corridor`: the plant read from the wiring, the
guidance taken out, bisection on gamma0 to 1e-6 rad) on each set's `npc_bank.json` scenario, in
this process: the set's TrimBankVehicle, bank actuator (starting at its command) and US76
atmosphere without its random profile (`atmosphere.profile_sigma` = 0), 0.1 s steps, exit at
122 km, the 400 km target apogee. The steep edge is the entry angle at which full lift up
(sigma = 0) exits on the target, the shallow edge full lift down (sigma = 180 deg); the third, at
sigma = 90 deg (no vertical lift, the centre of the control authority), is the set's nominal
entry. Corridor width = shallow - steep. `aotv-cosim corridor SCENARIO --set
atmosphere.profile_sigma=0` gives the same two edges. Run: `python -m aotv_cosim.studies.aerocapture_corridor`.
"""

import math
import tempfile

from aotv_cosim.simulation.loading import load_scenario
from aotv_cosim.studies import corridor as core
from aotv_cosim.studies.shipped import scenario as shipped

SCENARIOS = {"afe": "benchmark_aerocapture/afe/npc_bank.json", "aotv": "benchmark_aerocapture/aotv/npc_bank.json"}
"""The shipped scenario each configuration's corridor is flown from."""
UNPERTURBED = {"atmosphere.profile_sigma": 0.0}
"""The sets' US76 atmosphere without the random density profile their systems carry."""


def corridor(configuration: str) -> dict:
    """{"lift_up", "lift_down", "no_vertical_lift", "width"} in deg, and "lift_to_drag", of the
    configuration ("afe" or "aotv")."""
    scenario = load_scenario(shipped(SCENARIOS[configuration]), UNPERTURBED)
    plant = core.plant_of(scenario)
    assert scenario.outcome is not None  # the shipped scenarios state their outcome
    bounds = core.bounds("target", scenario.outcome.band, no_vertical_lift=True)
    with tempfile.TemporaryDirectory(prefix="aotv_corridor_study_") as tmp:
        paths = core.write_scenarios(scenario, plant, core.FRACTIONS, None, core.step_flown(scenario, None), tmp,
                                     UNPERTURBED)
        found = core.searches(plant, paths, bounds, core.nominal_gamma0(scenario), 1e-6)
        result = core.fly_in_process(found, core.gamma0_signal(scenario))
    up, down, mid = (math.degrees(result[b]["gamma0"]) for b in ("steep", "shallow", "no_vertical_lift"))
    return {"lift_up": up, "lift_down": down, "no_vertical_lift": mid, "width": down - up,
            "lift_to_drag": plant.lift_to_drag}


if __name__ == "__main__":
    for name in SCENARIOS:
        c = corridor(name)
        print(f"{name}: L/D {c['lift_to_drag']:.2f}: full lift up {c['lift_up']:.4f} deg, full lift down "
              f"{c['lift_down']:.4f} deg, width {c['width']:.4f} deg; "
              f"sigma = 90 deg at {c['no_vertical_lift']:.4f} deg")
