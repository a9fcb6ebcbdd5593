"""SSP export and import: schema validity, contents, reproducibility, round trip, refusals."""

import json
import zipfile

import pytest
from fmpy import read_model_description
from fmpy.ssp.ssd import read_ssd, read_ssv
from lxml import etree

from aotv_cosim.errors import InputError
from aotv_cosim.output.runner import run_scenario
from aotv_cosim.simulation.loading import load_scenario
from aotv_cosim.ssp.export import export_ssp
from aotv_cosim.model.ssp_names import NS, schema_dir
from aotv_cosim.simulation.loading import load_system
from aotv_cosim.fmu.build import built_fmu
from tests.helpers import NOMINAL, WIRING, error_lines, invoke, write_json

pytestmark = pytest.mark.integration


@pytest.fixture(scope="module")
def scenario():
    return load_scenario(NOMINAL)


@pytest.fixture(scope="module")
def ssp(scenario, tmp_path_factory):
    return export_ssp(scenario, tmp_path_factory.mktemp("ssp") / "nominal.ssp")


def xml_member(ssp, name):
    with zipfile.ZipFile(ssp) as archive:
        return etree.fromstring(archive.read(name))


def test_ssd_and_ssv_validate_against_fmpy_schemas(ssp):
    ssd_schema = etree.XMLSchema(etree.parse(str(schema_dir() / "SystemStructureDescription.xsd")))
    ssv_schema = etree.XMLSchema(etree.parse(str(schema_dir() / "SystemStructureParameterValues.xsd")))
    with zipfile.ZipFile(ssp) as archive:
        ssvs = [n for n in archive.namelist() if n.endswith(".ssv")]
    assert ssd_schema.validate(xml_member(ssp, "SystemStructure.ssd")), ssd_schema.error_log
    assert sorted(ssvs) == ["resources/atmosphere.ssv", "resources/guidance.ssv", "resources/vehicle.ssv"]
    for name in ssvs:
        assert ssv_schema.validate(xml_member(ssp, name)), (name, ssv_schema.error_log)
    assert read_ssd(str(ssp), validate=True).system.name == "aotv_time_linear"  # FMPy's own reader


def test_ssd_carries_components_connectors_units_connections_and_experiment(ssp, scenario):
    root = xml_member(ssp, "SystemStructure.ssd")
    system = scenario.system
    components = root.findall("ssd:System/ssd:Elements/ssd:Component", NS)
    assert [c.get("name") for c in components] == list(system.components)
    units = {u.get("name"): u.find("ssc:BaseUnit", NS).attrib for u in root.findall("ssd:Units/ssc:Unit", NS)}
    assert dict(units["kg/m3"]) == {"kg": "1", "m": "-3"} and dict(units["m/s2"]) == {"m": "1", "s": "-2"}
    connected = {(c.target, c.input) for c in system.connections}
    for node in components:
        comp = system.components[node.get("name")]
        with zipfile.ZipFile(ssp) as archive:
            packed = archive.read(node.get("source"))
        assert packed == comp.fmu.path.read_bytes()
        connectors = {c.get("name"): c for c in node.findall("ssd:Connectors/ssd:Connector", NS)}
        expected = [v.name for v in comp.fmu.variables.values() if v.causality in ("parameter", "output")
                    or (v.causality == "input" and (comp.name, v.name) in connected)]
        assert list(connectors) == expected
        for name, connector in connectors.items():
            var = comp.fmu.variables[name]
            assert connector.get("kind") == var.causality and connector.get("description") == var.description
            assert connector[0].tag == f"{{{NS['ssc']}}}{var.type}"
            assert connector[0].get("unit") == (var.unit or None) and (not var.unit or var.unit in units)
    pairs = [(c.get("startElement"), c.get("startConnector"), c.get("endElement"), c.get("endConnector"))
             for c in root.findall("ssd:System/ssd:Connections/ssd:Connection", NS)]
    assert pairs == [(c.source, c.output, c.target, c.input) for c in system.connections]
    experiment = root.find("ssd:DefaultExperiment", NS)
    assert float(experiment.get("startTime")) == 0.0 and float(experiment.get("stopTime")) == 300.0
    step = experiment.find("ssd:Annotations/ssc:Annotation/osp:Algorithm/osp:FixedStepAlgorithm", NS)
    assert float(step.get("baseStepSize")) == 0.1


def test_parameter_values_are_the_wiring_values_with_overrides(ssp, scenario):
    for comp in scenario.system.components.values():
        if not comp.parameters:
            continue
        values = {p.name: p.value for p in read_ssv(str(ssp), f"resources/{comp.name}.ssv").parameters}
        assert {k: type(v)(values[k]) for k, v in comp.parameters.items()} == comp.parameters
        assert set(values) == set(comp.parameters)


def test_export_is_byte_identical(scenario, ssp, tmp_path):
    assert export_ssp(scenario, tmp_path / "again.ssp").read_bytes() == ssp.read_bytes()


def test_imported_system_equals_the_wiring(ssp):
    wired, imported = load_system(WIRING, fmus=built_fmu), load_system(ssp, fmus=built_fmu)
    assert imported.connections == wired.connections
    for name, comp in wired.components.items():
        assert imported.components[name].parameters == comp.parameters
        assert imported.components[name].fmu.guid == comp.fmu.guid


def test_run_ssp_equals_run_scenario_and_records_guids(ssp, tmp_path):
    code, text = invoke("run", ssp, "--out", tmp_path / "ssp", "--no-plots")
    assert code == 0, text
    from_ssp = json.loads((tmp_path / "ssp" / "summary.json").read_text())
    from_json = run_scenario(load_scenario(NOMINAL), tmp_path / "json", make_plots=False).as_json()
    for signal, value in from_json["final"].items():
        assert from_ssp["final"][signal] == value, signal
    assert from_ssp["steps"] == 3000 and from_ssp["algorithm"] == "gauss-seidel"
    for name, entry in from_ssp["fmus"].items():
        assert entry["guid"] == read_model_description(entry["file"]).guid
        assert entry["guid"] == from_json["fmus"][name]["guid"]


def test_scenario_may_point_at_an_ssp(ssp, tmp_path, scenario_doc):
    scenario_doc["system"] = str(ssp)
    scenario_doc["parameters"] = {"vehicle.h0": 91000.0}
    loaded = load_scenario(write_json(tmp_path / "s.json", scenario_doc))
    assert loaded.system.path == ssp.resolve()
    assert loaded.system.components["vehicle"].parameters["h0"] == 91000.0
    assert len(loaded.expectations) == 7


def test_export_command(tmp_path):
    code, text = invoke("export-ssp", NOMINAL, "-o", tmp_path / "x.ssp", "--step", "0.2")
    assert code == 0, text
    assert "4 components, 7 connections, 0..300 s by 0.2 s" in text
    assert load_scenario(tmp_path / "x.ssp").step == 0.2


def rewrite(ssp, out, edit_ssd=None, extra=None):
    """A copy of `ssp` whose SSD text went through edit_ssd, with extra members added."""
    with zipfile.ZipFile(ssp) as src, zipfile.ZipFile(out, "w") as dst:
        for name in src.namelist():
            data = src.read(name)
            if name == "SystemStructure.ssd" and edit_ssd:
                data = edit_ssd(data.decode()).encode()
            dst.writestr(name, data)
        for name, data in (extra or {}).items():
            dst.writestr(name, data)
    return out


BAD = {
    "climbing member": (None, {"../evil.txt": "x"}, "escapes the extraction folder"),
    "source outside": (lambda t: t.replace('source="resources/Atmosphere.fmu"', 'source="../Atmosphere.fmu"'),
                       None, "not a relative path to a .fmu file inside the archive"),
    "named fmu": (lambda t: t.replace('source="resources/Atmosphere.fmu"', 'source="Atmosphere"'),
                  None, "not a relative path to a .fmu file"),
    "transformation": (lambda t: t.replace(
        'endElement="atmosphere" endConnector="h" />',
        'endElement="atmosphere" endConnector="h"><ssc:LinearTransformation factor="2.0" /></ssd:Connection>'),
        None, "connection transformations (LinearTransformation) are not supported"),
    "schema": (lambda t: t.replace('kind="output"', 'kind="sideways"', 1), None, "violates the SSP 1.0 schema"),
    "unknown variable": (lambda t: t.replace('endConnector="rho"', 'endConnector="density"'),
                         None, "has no variable 'density'"),
    "no step": (lambda t: t.replace('<ssc:Annotation type="org.aotv-cosim.experiment">', '<ssc:Annotation type="x">')
                .replace('type="com.opensimulationplatform"', 'type="y"'), None, "no communication step"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_archive_gives_one_clear_line(ssp, tmp_path, case):
    edit, extra, message = BAD[case]
    bad = rewrite(ssp, tmp_path / f"{case.replace(' ', '_')}.ssp", edit, extra)
    code, text = invoke("run", bad, "--out", tmp_path / "out")
    assert code == 2, text
    lines = set(error_lines(text))  # the runner's output repeats stderr after stdout
    assert len(lines) == 1 and message in min(lines) and str(bad) in min(lines), text


def test_unparsed_step_can_come_from_the_command_line(ssp, tmp_path):
    edit = BAD["no step"][0]
    bad = rewrite(ssp, tmp_path / "nostep.ssp", edit)
    with pytest.raises(InputError):
        load_scenario(bad)
    assert load_scenario(bad, step=0.5).step == 0.5


def test_default_experiment_stops_where_the_system_gets(tmp_path):
    """A scenario ending at a stop condition exports the last communication point before its
    event, not its own stop (400 s here, past the atmospheric exit); the archive runs to it, and
    the command line reports that stop."""
    exit_file = NOMINAL.with_name("aotv_time_linear_exit.json")
    exit_scenario = load_scenario(exit_file)
    event = run_scenario(exit_scenario, tmp_path / "run", make_plots=False).as_json()["event"]["time"]
    archive = export_ssp(exit_scenario, tmp_path / "exit.ssp")
    stop = float(xml_member(archive, "SystemStructure.ssd").find("ssd:DefaultExperiment", NS).get("stopTime"))
    assert stop < exit_scenario.stop
    assert event - exit_scenario.step < stop <= event
    assert round(stop / exit_scenario.step, 9) == round(stop / exit_scenario.step)
    summary = run_scenario(load_scenario(archive), tmp_path / "ssp", make_plots=False).as_json()
    assert summary["status"] == "completed" and summary["end_time"] == pytest.approx(stop)
    code, text = invoke("export-ssp", exit_file, "-o", tmp_path / "cli.ssp")
    assert code == 0, text
    assert f"0..{stop:g} s by {exit_scenario.step:g} s" in text, text


def test_every_ssv_is_one_named_parameter_set(ssp, scenario):
    """One ParameterSet name for the whole system: an engine that applies one named set (Ecos's
    --parameterSet) applies every component's values."""
    with zipfile.ZipFile(ssp) as archive:
        members = sorted(n for n in archive.namelist() if n.endswith(".ssv"))
    assert members == sorted(f"resources/{c.name}.ssv" for c in scenario.system.components.values()
                             if c.parameters)
    assert {xml_member(ssp, m).get("name") for m in members} == {"scenario"}
