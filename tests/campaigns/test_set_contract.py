"""The contract of a benchmark set (issue 36 item 6): what a law flown in it must provide, derived
from the set's scenarios; `validate --benchmark SET` and `benchmark --law` check a law against it,
every missing piece named in the user's own file; docs/benchmark.md shows it as the code derives it;
set names work from any folder."""

import json
import re

import pytest

import aotv_cosim
from aotv_cosim.campaigns import benchmark, contract
from aotv_cosim.errors import InputError, ValidationFailed
from tests.helpers import ROOT, SCENARIOS, error_lines, invoke, write_json

pytestmark = pytest.mark.integration

SHIPPED = ("benchmark_seed000", "benchmark_aerocapture/afe", "benchmark_aerocapture/aotv")
AFE = SCENARIOS / "benchmark_aerocapture"


def _law(tmp_path, system="afe_npc_bank.json", change=None):
    """A copy of a shipped aerocapture law's wiring, FMU paths absolute, changed by `change(doc)`."""
    doc = json.loads((AFE / "systems" / system).read_text())
    doc.pop("$schema")
    if change is not None:
        change(doc)
    return write_json(tmp_path / "my_law.json", doc)


@pytest.mark.parametrize("name", SHIPPED)
def test_every_law_of_a_shipped_set_meets_its_contract_from_any_folder(tmp_path, monkeypatch, name):
    monkeypatch.chdir(tmp_path)  # a set's name is found from any folder
    laws = sorted((SCENARIOS / name).glob("*.json"))
    assert [f for f, _ in aotv_cosim.validate(laws, benchmark=name)] == laws
    needs = contract.of_set(benchmark.scenarios_of(name))
    roles = {n.signal: n.role for n in needs}
    assert {roles["vehicle"], roles["atmosphere"], roles["actuator"]} == {"plant"}
    assert roles["actuator.command"] == "command" and roles["vehicle.gamma0"] == "parameter"
    assert roles["vehicle.h"] == "output" and "guidance" not in roles and "bank" not in roles


def test_the_aerocapture_contract_asks_for_the_bank_saturation_time_and_reversals():
    needs = {n.signal: n for n in contract.of_set(benchmark.scenarios_of("benchmark_aerocapture/afe"))}
    assert (needs["bank.saturation_time"].role, needs["bank.saturation_time"].unit) == ("output", "s")
    assert "the outcome's actuator: saturation time" in needs["bank.saturation_time"].uses
    assert (needs["actuator.reversals"].unit, needs["actuator.command"].unit) == ("1", "rad")
    assert dict(needs["vehicle"].values)["CL"] == 0.42 and needs["vehicle"].fmu == "TrimBankVehicle"


def test_docs_show_each_shipped_sets_contract_as_derived():
    text = (ROOT / "docs" / "benchmark.md").read_text()
    for name in SHIPPED:
        assert contract.markdown(contract.of_set(benchmark.scenarios_of(name))) in text, name


def test_validate_names_every_missing_piece_in_the_users_file(tmp_path):
    def broken(doc):
        doc["components"]["steering"] = doc["components"].pop("bank")      # the set reads bank.saturation_time
        doc["connections"] = [c.replace("bank.", "steering.") for c in doc["connections"]]
        doc["components"]["vehicle"]["parameters"]["mass"] = 1700.0       # not the set's plant
        doc["connections"].remove("steering.sigma -> actuator.command")    # the command not fed by the law
        doc["components"]["actuator"]["parameters"]["command"] = 0.0

    law = _law(tmp_path, change=broken)
    status, text = invoke("validate", law, "--benchmark", "benchmark_aerocapture/afe")
    assert status == 2
    assert error_lines(text) == [
        f"error: {law}: components.vehicle.parameters.mass: vehicle.mass is 1700.0: the set benchmark_aerocapture/afe "
        "flies 1600.0 in every law; give vehicle the set's mass: 1600.0",
        f"error: {law}: connections: actuator.command is not fed by your law: the set benchmark_aerocapture/afe feeds "
        "its command actuator.command [rad] (fed by bank.sigma in adaptive.json); connect your law's command: "
        "'LAW.OUTPUT -> actuator.command'",
        f"error: {law}: components: no component 'bank': the set benchmark_aerocapture/afe reads bank.saturation_time "
        "[s] (record; the outcome's actuator: saturation time); name the component of your law that provides it "
        "'bank'"]
    with pytest.raises(ValidationFailed) as caught:
        aotv_cosim.validate(law, benchmark="benchmark_aerocapture/afe")
    assert [f"error: {p}" for p in caught.value.problems] == error_lines(text)
    assert invoke("validate", law)[0] == 0  # a sound wiring: only the set's contract refuses it


def test_a_unit_or_a_causality_not_the_sets_is_named(tmp_path):
    law = _law(tmp_path)
    needs = contract.of_set(benchmark.scenarios_of("benchmark_aerocapture/afe"))
    from aotv_cosim.simulation.loading import load_system

    loaded = load_system(law)
    saturation = loaded.components["bank"].fmu.variables["saturation_time"]
    loaded.components["bank"].fmu.variables["saturation_time"] = type(saturation)(
        **{**saturation.__dict__, "unit": "min"})
    with pytest.raises(InputError, match=re.escape("components.bank: bank.saturation_time is in min: the set afe "
                                                   "reads bank.saturation_time [s]")):
        contract.check(needs, loaded, law, "afe")
    loaded.components["bank"].fmu.variables["saturation_time"] = type(saturation)(
        **{**saturation.__dict__, "causality": "parameter"})
    with pytest.raises(InputError, match=re.escape("bank (NpcBankGuidance) has saturation_time as parameter Real, "
                                                   "no output saturation_time: the set afe reads")):
        contract.check(needs, loaded, law, "afe")


def test_a_law_flown_with_benchmark_law_is_checked_before_any_run(tmp_path):
    law = _law(tmp_path, change=lambda doc: doc["components"]["vehicle"]["parameters"].update(CL=0.5))
    out = tmp_path / "out"
    status, text = invoke("benchmark", "benchmark_aerocapture/afe", "--law", law, "--runs", 1, "--out", out)
    assert status == 2 and error_lines(text) == [
        f"error: {law}: components.vehicle.parameters.CL: vehicle.CL is 0.5: the set benchmark_aerocapture/afe flies "
        "0.42 in every law; give vehicle the set's CL: 0.42"]
    assert not out.exists()


def test_validate_prints_the_contract_and_refuses_nothing_to_do(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    status, text = invoke("validate", "--benchmark", "benchmark_aerocapture/aotv")
    assert status == 0 and text.startswith("What a law of benchmark_aerocapture/aotv must provide:")
    assert "| `bank.saturation_time` | output | s |" in text
    status, text = invoke("validate")
    assert status == 2 and error_lines(text) == [
        "error: FILES: no file given; give at least one file to validate, or --benchmark SET for that set's contract"]


def test_an_outcome_actuator_without_a_recorded_saturation_time_is_refused(tmp_path):
    """Issue 36: `validate` passed an outcome.actuator naming a component that reports nothing."""
    scenario = AFE / "afe" / "npc_bank.json"
    doc = json.loads(scenario.read_text())
    for key in ("system", "dispersion_set"):
        doc[key] = str((scenario.parent / doc[key]).resolve())
    doc["montecarlo"]["outcome"]["actuator"] = "actuator"  # the BankActuator: no saturation_time
    path = write_json(tmp_path / "afe.json", doc)
    status, text = invoke("validate", path)
    assert status == 2 and error_lines(text) == [
        f"error: {path}: montecarlo.outcome.actuator: actuator has no output saturation_time, which the outcome "
        "reports as the actuator's saturation time; name the component that outputs saturation_time (s), or leave "
        "actuator out"]
    doc["montecarlo"]["outcome"]["actuator"] = "bank"
    doc["record"].remove("bank.saturation_time")
    write_json(path, doc)
    status, text = invoke("validate", path)
    assert status == 2 and error_lines(text) == [
        f"error: {path}: montecarlo.outcome.actuator: bank.saturation_time is not recorded: the outcome's saturation "
        "time would be nan; add bank.saturation_time to record"]
