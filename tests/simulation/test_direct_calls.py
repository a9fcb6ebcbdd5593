"""Direct in-process calls of this package's FMUs (`simulation.direct_instance`) against the C path:
the same timeseries.csv byte for byte, the same failures, the watchdog still ends a hung step,
and a slave class run as an FMU with no FMU file."""

import ctypes
import json
from types import SimpleNamespace
import math

import pytest

from aotv_cosim.model.variable_types import Strings
from aotv_cosim.simulation.direct_instance import DirectInstance, built_here
from aotv_cosim.simulation.instance import Slots
from aotv_cosim.simulation.master import Master
from aotv_cosim.output.runner import write_run
from aotv_cosim.simulation.loading import load_scenario
from tests.helpers import SCENARIOS

pytestmark = pytest.mark.integration  # builds and runs the package's FMUs

REPRESENTATIVE = ["aotv_time_linear_nominal.json",  # seed 000
                  "plane_change_mae_guided.json",  # seed 001
                  "entry_full_nominal.json",  # seed 002
                  "shuttle_lqr_150kft.json",  # seed 003
                  "aotv_time_linear_exit_accurate.json"]  # extrapolated inputs, located exit


WALL_CLOCK = ("solve_time", "cycle_cpu")
"""Recorded outputs that are wall-clock or CPU times (a guidance law's solve and cycle times):
left out of the bytes."""


def without_wall_clock(csv: bytes) -> bytes:
    """timeseries.csv without its wall-clock columns, its other bytes as they are."""
    lines = csv.split(b"\n")
    keep = [k for k, name in enumerate(lines[0].split(b","))
            if not name.decode().endswith(WALL_CLOCK)]
    return b"\n".join(b",".join(line.split(b",")[k] for k in keep) if line else line for line in lines)


def both_paths(scenario_path, tmp_path, **changes):
    """(summary c, summary direct, csv c, csv direct) of one scenario run on both call paths, the
    csv files without their wall-clock columns."""
    out = []
    for calls in ("c", "direct"):
        scenario = load_scenario(scenario_path, **changes)
        summary = write_run(scenario, tmp_path / calls, make_plots=False, fmi_calls=calls).summary.as_json()
        out.append((summary, without_wall_clock((tmp_path / calls / "timeseries.csv").read_bytes())))
    (c, c_csv), (d, d_csv) = out
    return c, d, c_csv, d_csv


@pytest.mark.parametrize("name", REPRESENTATIVE)
def test_direct_calls_give_the_c_paths_timeseries_byte_for_byte(name, tmp_path):
    c, d, c_csv, d_csv = both_paths(SCENARIOS / name, tmp_path)
    assert c["status"] == d["status"] and c["stop_reason"] == d["stop_reason"]
    assert c_csv == d_csv and len(c_csv) > 1000
    assert c["fmi_calls"] == "c" and d["fmi_calls"] == "direct"
    assert {f["fmi_calls"] for f in c["fmus"].values()} == {"c"}
    assert {f["fmi_calls"] for f in d["fmus"].values()} == {"direct"}


def adaptive(tmp_path, source, step):
    doc = json.loads(source.read_text())
    doc.update(system=str(source.parent / doc["system"]), step=step, expectations=[], plots=[])
    path = tmp_path / "adaptive.json"
    path.write_text(json.dumps(doc))
    return path


def test_error_controlled_run_is_the_same_on_both_paths(tmp_path):
    """Step doubling saves and restores every FMU's state: the direct snapshots give the same run."""
    path = adaptive(tmp_path, SCENARIOS / "aotv_time_linear_exit.json",
                    {"size": 0.5, "tolerance": {"vehicle.h": 1.0}})
    c, d, c_csv, d_csv = both_paths(path, tmp_path)
    assert c["step_control"] == d["step_control"] and c["event"] == d["event"]
    assert c_csv == d_csv


def test_only_this_packages_fmus_are_called_directly():
    scenario = load_scenario(SCENARIOS / "aotv_time_linear_nominal.json")
    assert all(built_here(comp.fmu) for comp in scenario.system.components.values())


@pytest.mark.parametrize("kind", [1, 2, 3], ids=["raise", "error-status", "nan"])
def test_a_failing_fmu_fails_the_run_as_on_the_c_path(kind, tmp_path, wiring_doc):
    """The FaultInjector FMU (fmus_src/FaultInjector.py) raises, refuses its step or outputs NaN at
    t = 2 s: the same status, error, error_detail (with the FMU's log) and rows on both paths."""
    from tests.helpers import write_json

    wiring_doc["components"]["fault"] = {"fmu": "FaultInjector",
                                         "parameters": {"fault_kind": kind, "fault_time": 2.0}}
    wiring_doc["connections"].remove("guidance.u -> actuator.command")
    wiring_doc["connections"] += ["guidance.u -> fault.u", "fault.y -> actuator.command"]
    wiring = write_json(tmp_path / "wiring.json", wiring_doc)
    path = write_json(tmp_path / "scenario.json", {"system": str(wiring), "stop": 5.0, "step": 0.1,
                                                   "record": ["vehicle.h", "guidance.u", "fault.y"]})
    c, d, c_csv, d_csv = both_paths(path, tmp_path)
    assert c["status"] == "failed"
    for key in ("status", "stop_reason", "error", "error_detail"):
        assert c[key] == d[key], key
    assert c_csv == d_csv


def shipped_scenarios() -> list:
    """The single-run scenarios of scenarios/ (not the compare, Monte Carlo or benchmark files)."""
    return sorted(p.name for p in SCENARIOS.glob("*.json")
                  if "system" in json.loads(p.read_text()) and "dispersions" not in json.loads(p.read_text()))


@pytest.mark.slow
@pytest.mark.parametrize("name", shipped_scenarios())
def test_every_shipped_scenario_is_the_same_on_both_paths(name, tmp_path):
    c, d, c_csv, d_csv = both_paths(SCENARIOS / name, tmp_path)
    assert (c["status"], c["stop_reason"], c_csv) == (d["status"], d["stop_reason"], d_csv)


def test_a_slave_class_runs_as_an_in_process_fmu_without_a_file():
    """`DirectInstance.from_class`: a pythonfmu slave class stepped with no FMU file (a fake FMU
    for master unit tests) through the instance contract; its log reaches `messages`, a false
    do_step is a typed terminate request."""
    from pythonfmu import Fmi2Causality, Fmi2Slave, Real
    from pythonfmu.enums import Fmi2Status

    class Counter(Fmi2Slave):
        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.rate, self.x = 2.0, 0.0
            self.register_variable(Real("rate", causality=Fmi2Causality.input))
            self.register_variable(Real("x", causality=Fmi2Causality.output))

        def do_step(self, current_time, step_size):
            self.x += self.rate * step_size
            self.log(f"stepped to {current_time + step_size}", Fmi2Status.ok)
            return self.x < 1.0

    inst = DirectInstance.from_class("counter", Counter)
    inst.set_values({"rate": 4.0})
    inst.enter_initialization()
    inst.exit_initialization()
    buffer = (ctypes.c_double * 1)()
    read_x = inst.getter("Real", Slots((inst.info.variables["x"].vr,), (0,)), buffer, Strings())
    assert inst.step(0.0, 0.1).ok
    read_x(0.1)
    assert buffer[0] == pytest.approx(0.4)
    assert inst.messages[-1] == ("ok", "stepped to 0.1")
    assert inst.step(0.1, 0.1).ok
    ended = inst.step(0.2, 0.1)  # x reaches 1.2: do_step returns False
    assert (ended.outcome, ended.status, ended.last_successful_time) == ("terminate", 2, 0.2)
    request = inst.refusal(ended)
    assert type(request).__name__ == "TerminateRequest" and request.last_successful_time == 0.2
    assert math.isclose(inst.get_value("x"), 1.2)
    inst.close()


def test_the_watchdog_ends_a_hung_direct_step(tmp_path):
    """A step that hangs in the slave's Python is ended by the step watchdog on the direct path."""
    import time

    scenario = load_scenario(SCENARIOS / "aotv_time_linear_nominal.json", stop=1.0)
    scenario.step_timeout = 0.5
    master = Master(scenario, fmi_calls="direct")
    real_build = master._build_plans

    def build_then_hang():
        real_build()
        master.instances["guidance"].slave.do_step = lambda t, h: time.sleep(30)
    master._build_plans = build_then_hang
    t0 = time.monotonic()
    outcome = master.run(SimpleNamespace(record=lambda t, r: None))
    assert time.monotonic() - t0 < 5
    assert outcome.status == "failed" and "step timeout" in outcome.error and "guidance" in outcome.error


def test_dispersed_runs_of_a_benchmark_set_are_the_same_on_both_paths():
    """Two draws of the seed-000 robust benchmark (extrapolated inputs, exit located) run one after
    the other on pooled instances (the second on reset FMUs, as a campaign worker does)."""
    from aotv_cosim.campaigns.draws import draw

    scenario = load_scenario(SCENARIOS / "benchmark_seed000" / "robust.json")
    recorded = {}
    for calls in ("c", "direct"):
        pool, runs = {}, []
        for k in range(2):
            rows = []
            master = Master(scenario, overrides=draw(scenario.dispersions, 0, k), pool=pool, fmi_calls=calls)
            outcome = master.run(SimpleNamespace(record=lambda t, r, rows=rows: rows.extend(zip(t, r))))
            runs.append((outcome.status, outcome.stop_reason, outcome.event, [(t, bytes(r)) for t, r in rows]))
        for inst in pool.values():
            inst.close()
        recorded[calls] = runs
    assert recorded["c"][0][0] == "completed" and recorded["c"][0][2] is not None
    assert recorded["c"] == recorded["direct"]


@pytest.mark.parametrize("calls", ["c", "direct", None])
def test_the_command_line_and_the_api_choose_the_call_path(calls, tmp_path):
    """`aotv-cosim run --fmi-calls` and `api.run(fmi_calls=)`; summary.json says which path ran
    (direct by default for this package's FMUs)."""
    from click.testing import CliRunner

    from aotv_cosim import api
    from aotv_cosim.cli import main

    args = ["run", str(SCENARIOS / "aotv_time_linear_nominal.json"), "--stop", "1", "--no-plots",
            "--out", str(tmp_path / "cli")] + (["--fmi-calls", calls] if calls else [])
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 0, result.output
    summary = json.loads((tmp_path / "cli" / "summary.json").read_text())
    expected = calls or "direct"
    assert summary["fmi_calls"] == expected
    assert {f["fmi_calls"] for f in summary["fmus"].values()} == {expected}
    ran = api.run(SCENARIOS / "aotv_time_linear_nominal.json", stop=1.0, fmi_calls=calls)
    assert ran.summary["fmi_calls"] == expected
    assert without_wall_clock((tmp_path / "cli" / "timeseries.csv").read_bytes()).startswith(b"time,")


def _with_member(source, target, name, change):
    """A copy of the FMU archive `source` at `target` with member `name` made `change(old bytes or
    None)` (None: left out)."""
    import zipfile

    with zipfile.ZipFile(source) as old, zipfile.ZipFile(target, "w") as new:
        members = {n: old.read(n) for n in old.namelist()}
        members[name] = change(members.get(name))
        for member, data in members.items():
            if data is not None:
                new.writestr(member, data)
    return target


@pytest.mark.parametrize("edit", ["guid in modelDescription", "guid file", "guid file agrees",
                                  "no guid file, guid in modelDescription", "no guid file"])
def test_the_direct_path_refuses_a_guid_the_fmu_was_not_built_with(tmp_path, edit):
    """As the C wrapper refuses to instantiate with another GUID, so does the direct path: the
    build's GUID is read from resources/aotv_cosim_guid.txt when the FMU has it, else (an FMU built
    before that file) derived again by the build's rule from its source hash and modelDescription."""
    import fmpy

    from aotv_cosim.fmu.build import TOKEN_FILE, built_fmu
    from tests.helpers import write_json

    source = built_fmu("Atmosphere")
    guid = fmpy.read_model_description(str(source)).guid
    other = "{00000000-0000-5000-8000-000000000000}"
    if edit.startswith("no guid file"):
        source = _with_member(source, tmp_path / "without.fmu", TOKEN_FILE, lambda _: None)
    if edit.endswith("guid in modelDescription"):
        _with_member(source, tmp_path / "Atm.fmu", "modelDescription.xml",
                     lambda xml: xml.replace(guid.encode(), other.encode()))
    elif edit == "no guid file":
        _with_member(source, tmp_path / "Atm.fmu", TOKEN_FILE, lambda _: None)
    else:
        _with_member(source, tmp_path / "Atm.fmu", TOKEN_FILE,
                     lambda _: (guid if edit == "guid file agrees" else other).encode())
    write_json(tmp_path / "w.json", {"components": {"a": {"fmu": "Atm.fmu", "parameters": {"h": 80000.0}}},
                                     "connections": []})
    path = write_json(tmp_path / "s.json", {"system": "w.json", "stop": 1.0, "step": 0.5})
    summary = write_run(load_scenario(path), tmp_path / "out", make_plots=False, fmi_calls="direct").summary.as_json()
    if edit in ("guid file agrees", "no guid file"):
        assert summary["status"] == "completed", summary["error"]
        assert summary["fmus"]["a"]["fmi_calls"] == "direct"
    else:
        assert summary["status"] == "failed" and "instantiate" in summary["error"] and "GUID" in summary["error"]
