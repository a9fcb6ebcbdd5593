"""Sweeps over a grid of parameters, and the entry corridor of the seed-000 pass."""

import math
import re

import pytest

import aotv_cosim
from aotv_cosim.campaigns.sweep import grid_points
from aotv_cosim.options.checks import parse_grid
from aotv_cosim.errors import InputError
from tests.helpers import SCENARIOS

PASS = SCENARIOS / "benchmark_seed000" / "time_linear.json"


def test_grids_are_parsed_and_combined():
    assert parse_grid("vehicle.gamma0=-0.03:-0.01:3") == ("vehicle.gamma0", (-0.03, -0.02, -0.01))
    assert parse_grid("atmosphere.density_factor=0.8,1.2") == ("atmosphere.density_factor", (0.8, 1.2))
    assert grid_points([("a.x", [1.0, 2.0]), ("b.y", [3.0])]) == [{"a.x": 1.0, "b.y": 3.0}, {"a.x": 2.0, "b.y": 3.0}]
    for bad in ("gamma0=-0.03:-0.01:3", "vehicle.gamma0=1:2", "vehicle.gamma0=a,b", "vehicle.gamma0=nan"):
        with pytest.raises(InputError):
            parse_grid(bad)


@pytest.mark.integration
def test_sweep_gives_one_tidy_row_per_point_with_units(tmp_path, drawn):
    frame = aotv_cosim.sweep(PASS, {"vehicle.gamma0": [-0.022, -0.02, -0.018]}, workers=1, out=tmp_path)
    assert list(frame["vehicle.gamma0"]) == [-0.022, -0.02, -0.018]
    assert list(frame["status"]) == ["completed"] * 3
    units = frame.attrs["units"]
    assert units["vehicle.gamma0"] == "rad" and units["outcome.apogee_error"] == "m" and units["min.vehicle.h"] == "m"
    error = list(frame["outcome.apogee_error"])
    assert error[0] < error[1] < error[2]  # a shallower entry keeps more energy
    single = aotv_cosim.run(PASS, set={"vehicle.gamma0": -0.018}).outcome
    assert math.isclose(float(single["apogee_error"]), error[2], rel_tol=1e-12)
    assert (tmp_path / "sweep.png").is_file() and (tmp_path / "sweep.parquet").is_file()
    panels = drawn[(tmp_path / "sweep.png").resolve()].panels
    assert panels[0].ylabel == "outcome.apogee_error [km]" and "capture band" in panels[0].legend
    assert all(p.xlabel == "vehicle.gamma0 [rad]" and p.collections == 1 for p in panels)  # the 3 points
    assert "vehicle.gamma0 [rad]" in (tmp_path / "sweep.csv").read_text().splitlines()[0]


@pytest.mark.integration
def test_the_corridor_brackets_the_nominal_entry_and_each_bound_lands_on_the_band_edge(tmp_path, drawn):
    tolerance = 100.0
    corridor = aotv_cosim.corridor(PASS, lift_to_drag=5.0, aim="band", tolerance=tolerance, out=tmp_path)
    assert (corridor["plant"], corridor["control"], corridor["removed"]) == ("lift", "vehicle.u_lift", ["guidance"])
    steep, shallow = corridor["steep"], corridor["shallow"]
    assert steep["gamma0"] < corridor["nominal_gamma0"] == -0.02 < shallow["gamma0"]
    assert math.isclose(corridor["width_rad"], shallow["gamma0"] - steep["gamma0"])
    band = corridor["band_m"]
    for bound, case, edge in ((steep, "lift_up", -band), (shallow, "lift_down", band)):
        checked = aotv_cosim.run(tmp_path / f"{case}.json", set={"vehicle.gamma0": bound["gamma0"]}).outcome
        assert abs(float(checked["apogee_error"]) - edge) <= tolerance, (case, checked["apogee_error"])
    assert (tmp_path / "corridor.png").is_file()
    panel, = drawn[(tmp_path / "corridor.png").resolve()].panels
    assert (panel.xlabel, panel.ylabel) == ("entry flight-path angle gamma0 [deg]", "exit apogee error [km] (clipped "
                                                                                     "at +-80)")
    assert panel.title.startswith("corridor ") and f"width {corridor['width_deg']:.4f} deg" in panel.title
    assert {"full lift up (L/D = 5)", "full lift down (L/D = 5)", "nominal entry", "corridor"} <= set(panel.legend)
    with pytest.raises(InputError, match="does not cross"):
        aotv_cosim.corridor(PASS, lift_to_drag=5.0, bracket=(-0.03, -0.025))


@pytest.mark.integration
def test_the_theoretical_corridor_exits_on_the_target_to_the_angle_tolerance(tmp_path):
    """Aim "target" (the default): each bound's final bracket is at most the angle tolerance wide and
    its two runs exit below and above the target; the band's corridor holds the target's."""
    corridor = aotv_cosim.corridor(PASS, lift_to_drag=5.0, angle_tolerance=1e-6, out=tmp_path, workers=2)
    capture = aotv_cosim.corridor(PASS, lift_to_drag=5.0, aim="band", angle_tolerance=1e-6, workers=2)
    for name in ("steep", "shallow"):
        bound = corridor[name]
        low, high = bound["bracket"]
        assert bound["edge"] == 0.0 and 0.0 < high - low <= 1e-6 and bound["gamma0"] in (low, high)
        assert bound["bracket_errors"][0] < 0.0 <= bound["bracket_errors"][1]
    assert capture["steep"]["gamma0"] < corridor["steep"]["gamma0"] < corridor["shallow"]["gamma0"] \
        < capture["shallow"]["gamma0"]


@pytest.mark.integration
def test_corridor_refuses_lift_to_drag_where_it_would_be_ignored_or_is_missing(tmp_path):
    with pytest.raises(InputError, match=r"--lift-to-drag: the vehicle is steered by a lift acceleration "
                                         r"\(vehicle.u_lift, m/s2\) and states no lift limit; give the L/D"):
        aotv_cosim.corridor(PASS, out=tmp_path / "seed000")
    bank = SCENARIOS / "benchmark_aerocapture" / "afe" / "time_linear.json"
    with pytest.raises(InputError, match=r"--lift-to-drag: the vehicle is steered by its bank angle \(vehicle.sigma, "
                                         r"rad\) and flies C_L/C_D = 0.3 of its parameters: --lift-to-drag 0.3 would "
                                         r"be ignored; leave --lift-to-drag out"):
        aotv_cosim.corridor(bank, lift_to_drag=0.3, out=tmp_path / "afe")
    with pytest.raises(InputError, match=r"--set: guidance.tf is a value of the guidance the corridor takes out"):
        aotv_cosim.corridor(bank, set={"guidance.tf": 400.0}, out=tmp_path / "afe2")
    assert not any(tmp_path.iterdir())  # refused before anything was written


@pytest.mark.integration
def test_a_law_scenario_with_other_dispersions_is_refused(tmp_path):
    import json

    from aotv_cosim.campaigns.benchmark import run_benchmark
    from aotv_cosim.options import BenchmarkOptions
    from tests.helpers import write_json

    doc = json.loads(PASS.read_text())
    doc["system"] = str((PASS.parent / doc["system"]).resolve())
    doc.pop("dispersion_set")
    doc["dispersions"] = {"vehicle.gamma0": {"distribution": "uniform", "low": -0.021, "high": -0.019}}
    mine = write_json(tmp_path / "mine.json", doc)
    with pytest.raises(InputError, match=re.escape("its dispersions differ from those of time_linear.json")):
        run_benchmark(BenchmarkOptions(scenario_set=PASS, runs=2, out=tmp_path / "o", laws=[mine]))
    wiring = PASS.parent / doc["system"]
    with pytest.raises(InputError, match="a wiring, not a scenario set; give it as --law"):
        run_benchmark(BenchmarkOptions(scenario_set=wiring, runs=2, out=tmp_path / "o"))
