"""The corridor command on every shipped scenario that classifies its runs, and the aerocapture
study flown by the command's code: the AFE and AOTV edges of an independent tool to 0.001 deg."""

import json
import math

import pytest

import aotv_cosim
from aotv_cosim.simulation.loading import load_scenario
from aotv_cosim.studies import aerocapture_corridor as study
from aotv_cosim.studies import corridor as core
from tests.helpers import SCENARIOS

EDGES_DEG = {"afe": (-5.3932, -4.0640), "aotv": (-13.9417, -4.1529)}
"""Full lift up / full lift down edges (deg) of the AFE- and AOTV-class vehicles on the 400 km
target, recomputed in another public aerocapture tool with the same constants and an independent
US76 (issue 36: they agreed with this package's study to 0.0003 deg)."""
TOLERANCE_DEG = 0.001
"""What the edges must agree to: the issue's figure. Its parts, measured: the bisection ends when
the gamma0 bracket is 1e-6 rad (5.7e-5 deg) wide; the passes at 0.1 s steps lie within 0.00005 deg
of those at 0.05 s and within 0.00012 deg of the values above (AOTV steep edge; at the sets' own
1 s steps it would be 0.0085 deg off, hence the corridor's 0.1 s cap)."""

CLASSIFIED = sorted(p for p in SCENARIOS.rglob("*.json")
                    if '"outcome"' in p.read_text() and "dispersions" not in p.parent.name
                    and "systems" not in p.parent.name)


@pytest.mark.integration
@pytest.mark.parametrize("configuration", ["afe", "aotv"])
def test_the_command_gives_the_studys_edges_and_the_independent_tools_to_a_thousandth_of_a_degree(tmp_path,
                                                                                                    configuration):
    scenario = SCENARIOS / "benchmark_aerocapture" / configuration / "npc_bank.json"
    result = aotv_cosim.corridor(scenario, set=study.UNPERTURBED, workers=2, out=tmp_path)
    assert (result["plant"], result["control"], result["removed"]) == ("bank", "vehicle.sigma", ["bank"])
    assert result["lift_to_drag"] == pytest.approx({"afe": 0.3, "aotv": 1.0}[configuration], rel=1e-12)
    steep, shallow = (math.degrees(result[b]["gamma0"]) for b in ("steep", "shallow"))
    assert (steep, shallow) == pytest.approx(EDGES_DEG[configuration], abs=TOLERANCE_DEG)
    flown = study.corridor(configuration)  # in this process, by the same code
    assert (flown["lift_up"], flown["lift_down"]) == (steep, shallow)  # the same runs, bit for bit
    assert flown["lift_up"] < flown["no_vertical_lift"] < flown["lift_down"]
    nominal = math.degrees(result["nominal_gamma0"])  # the sets' entry: the sigma = 90 deg pass on the target
    assert flown["no_vertical_lift"] == pytest.approx(nominal, abs=TOLERANCE_DEG)


@pytest.mark.integration
@pytest.mark.parametrize("path", CLASSIFIED, ids=[str(p.relative_to(SCENARIOS)) for p in CLASSIFIED])
def test_every_shipped_scenario_that_classifies_its_runs_gives_its_plant(tmp_path, path):
    """The plant is read from the wiring: every law of an aerocapture set leaves the same bank-angle
    plant (vehicle, actuator, atmosphere) at its own L/D; a seed-000 scenario a lift-acceleration one."""
    scenario = load_scenario(path)
    plant = core.plant_of(scenario)
    core.check_flyable(scenario, plant)
    lift_to_drag = None if plant.kind == core.BANK else 5.0
    paths = core.write_scenarios(scenario, plant, ["lift_up"], lift_to_drag, 0.1, tmp_path)
    wiring = json.loads((tmp_path / "lift_up_wiring.json").read_text())
    if "benchmark_aerocapture" in path.parts:
        configuration = path.parent.name
        assert (plant.kind, plant.control, plant.command) == ("bank", "vehicle.sigma", "actuator.command")
        assert plant.lift_to_drag == pytest.approx({"afe": 0.3, "aotv": 1.0}[configuration], rel=1e-12)
        assert set(wiring["components"]) == {"vehicle", "atmosphere", "actuator"}
        reference = json.loads((SCENARIOS / "benchmark_aerocapture" / "systems" /
                                f"{configuration}_npc_bank.json").read_text())
        assert {k: v for k, v in wiring["components"].items() if k != "actuator"} == \
            {k: v for k, v in reference["components"].items() if k in ("vehicle", "atmosphere")}
        assert wiring["components"]["actuator"]["parameters"]["command"] == 0.0
    else:
        assert (plant.kind, plant.control, plant.command, plant.lift_to_drag) == \
            ("lift", "vehicle.u_lift", "actuator.command", None)
        assert set(wiring["components"]) == {"vehicle", "atmosphere", "actuator", core.LIFT_COMPONENT}
    assert load_scenario(paths["lift_up"]).outcome is not None
