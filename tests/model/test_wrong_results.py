"""Inputs that used to run and give wrong results: SSV units, non-Real ports, CSV-breaking names,
duplicate SSP components and members and an unknown SSP algorithm."""

import zipfile

import pytest

from aotv_cosim.errors import InputError
from aotv_cosim.simulation.loading import load_scenario
from aotv_cosim.simulation.loading import load_system
from aotv_cosim.fmu.build import built_fmu
from tests.helpers import one_line, write_json
from tests.model.archives import SSD, rewritten, ssd_text

VEHICLE_SSV = "resources/vehicle.ssv"
KM = '<ssc:Unit name="km"><ssc:BaseUnit m="1" factor="1000" /></ssc:Unit>'


def _ssv_text(ssp):
    with zipfile.ZipFile(ssp) as archive:
        return archive.read(VEHICLE_SSV).decode()


def _h0_in_km(ssp, out, define=True):
    text = _ssv_text(ssp).replace('<ssv:Real value="90000.0" unit="m" />', '<ssv:Real value="80" unit="km" />')
    if define:
        text = text.replace("<ssv:Units>", "<ssv:Units>" + KM)
    return rewritten(ssp, out, {VEHICLE_SSV: text})


@pytest.mark.integration
def test_ssv_values_in_a_defined_unit_are_converted(nominal_ssp, tmp_path):
    """h0 = 80 km (km defined as 1000 m in the SSV's Units) sets the FMU's h0 (m) to 80000."""
    system = load_system(_h0_in_km(nominal_ssp, tmp_path / "km.ssp"), fmus=built_fmu)
    assert system.components["vehicle"].parameters["h0"] == pytest.approx(80000.0)


@pytest.mark.integration
def test_ssv_values_in_an_undefined_or_other_unit_are_refused(nominal_ssp, tmp_path):
    one_line(["validate", _h0_in_km(nominal_ssp, tmp_path / "km.ssp", define=False)],
             "parameter h0", "unit 'km' is not defined")
    text = _ssv_text(nominal_ssp).replace('<ssv:Real value="8200.0" unit="m/s" />',
                                          '<ssv:Real value="8.2" unit="km" />')
    other = rewritten(nominal_ssp, tmp_path / "other.ssp", {VEHICLE_SSV: text.replace("<ssv:Units>",
                                                                                      "<ssv:Units>" + KM)})
    one_line(["validate", other], "parameter v0", "cannot be converted to the FMU's unit 'm/s'")


@pytest.mark.integration
def test_duplicate_ssp_components_and_members_are_refused(nominal_ssp, tmp_path):
    text = ssd_text(nominal_ssp)
    twice = text.replace('<ssd:Component name="atmosphere"', '<ssd:Component name="vehicle"', 1)
    one_line(["validate", rewritten(nominal_ssp, tmp_path / "c.ssp", {SSD: twice})], "two components are named "
                                                                                     "'vehicle'")
    with pytest.warns(UserWarning, match="Duplicate name"):
        doubled = rewritten(nominal_ssp, tmp_path / "m.ssp", add={SSD: text})
    one_line(["validate", doubled], "appears twice")
    ssv = _ssv_text(nominal_ssp)
    repeated = ssv.replace('<ssv:Parameter name="v0">', '<ssv:Parameter name="h0"><ssv:Real value="1.0" unit="m" />'
                           '</ssv:Parameter><ssv:Parameter name="v0">')
    one_line(["validate", rewritten(nominal_ssp, tmp_path / "p.ssp", {VEHICLE_SSV: repeated})], "'h0' is given twice")


def _crafted_fmu(path, variables):
    """An FMU archive (modelDescription and a placeholder binary) with the given ScalarVariables:
    [(name, type, causality)]; it loads and validates but is never instantiated here."""
    from fmpy import platform, sharedLibraryExtension

    rows, outputs = [], []
    for k, (name, kind, causality) in enumerate(variables):
        start = f'<{kind} start="0"/>' if causality != "output" else f"<{kind}/>"
        variability = "continuous" if kind == "Real" else "discrete"
        extra = ' initial="exact"' if causality == "parameter" else ""
        variability = "fixed" if causality == "parameter" else variability
        rows.append(f'<ScalarVariable name="{name}" valueReference="{k}" causality="{causality}" '
                    f'variability="{variability}"{extra}>{start}</ScalarVariable>')
        if causality == "output":
            outputs.append(f'<Unknown index="{k + 1}" dependencies=""/>')
    xml = f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="Crafted" guid="{{00000000-0000-0000-0000-000000000002}}">
  <CoSimulation modelIdentifier="Crafted"/>
  <ModelVariables>{''.join(rows)}</ModelVariables>
  <ModelStructure><Outputs>{''.join(outputs)}</Outputs></ModelStructure>
</fmiModelDescription>
"""
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("modelDescription.xml", xml)
        archive.writestr(f"binaries/{platform}/Crafted{sharedLibraryExtension}", "placeholder")
    return path


def test_typed_ports_connect_by_equal_type_or_an_explicit_conversion(tmp_path):
    """Integer and Boolean ports connect to ports of their type; an Integer output feeds a Real
    input only when the wiring says '(as Real)'; the default record holds every output; a stop
    condition crossing a threshold needs a Real or Integer output."""
    _crafted_fmu(tmp_path / "c.fmu", [("count", "Integer", "output"), ("flag", "Boolean", "output"),
                                      ("n_in", "Integer", "input"), ("y", "Real", "output"),
                                      ("u", "Real", "input"), ("mode", "Integer", "parameter")])
    wiring = {"components": {"a": {"fmu": "c.fmu", "parameters": {"n_in": 1, "mode": 2, "u": 0.0}},
                             "b": {"fmu": "c.fmu", "parameters": {"mode": 3}}},
              "connections": ["a.count -> b.n_in", "a.count -> b.u"]}
    write_json(tmp_path / "w.json", wiring)
    one_line(["validate", tmp_path / "w.json"], "a.count -> b.u", "type mismatch: Integer -> Real", "(as Real)")
    wiring["connections"][1] = "a.count -> b.u (as Real)"
    write_json(tmp_path / "w.json", wiring)
    scenario = {"system": "w.json", "stop": 1, "step": 0.5}
    write_json(tmp_path / "s.json", scenario)
    loaded = load_scenario(tmp_path / "s.json")
    assert loaded.record == ["a.count", "a.flag", "a.y", "b.count", "b.flag", "b.y"]
    assert loaded.system.components["a"].parameters == {"n_in": 1, "mode": 2, "u": 0.0}
    assert str(loaded.system.connections[1]) == "a.count -> b.u (as Real)"
    wiring["connections"][1] = "a.flag -> b.n_in"
    write_json(tmp_path / "w.json", wiring)
    one_line(["validate", tmp_path / "w.json"], "a.flag -> b.n_in", "type mismatch: Boolean -> Integer")
    wiring["connections"] = ["a.count -> b.n_in", "a.count -> b.u (as Real)"]
    write_json(tmp_path / "w.json", wiring)
    write_json(tmp_path / "s.json", {**scenario, "stop_conditions": [{"signal": "b.flag", "crosses": 1}]})
    one_line(["validate", tmp_path / "s.json"], "stop_conditions[0].signal", "b.flag is a Boolean",
             "Real or Integer")


def test_a_comma_in_a_recorded_name_is_refused(tmp_path):
    _crafted_fmu(tmp_path / "c.fmu", [("a,b", "Real", "output"), ("y", "Real", "output")])
    write_json(tmp_path / "w.json", {"components": {"c": {"fmu": "c.fmu"}}, "connections": []})
    write_json(tmp_path / "s.json", {"system": "w.json", "stop": 1, "step": 0.5})
    one_line(["validate", tmp_path / "s.json"], "record[0] (default: every output)", "comma")
    write_json(tmp_path / "s.json", {"system": "w.json", "stop": 1, "step": 0.5, "record": ["c.y"]})
    assert load_scenario(tmp_path / "s.json").record == ["c.y"]


@pytest.mark.integration
def test_an_invalid_ssp_algorithm_is_refused(nominal_ssp, tmp_path):
    text = ssd_text(nominal_ssp).replace('algorithm="gauss-seidel"', 'algorithm="rk4"')
    with pytest.raises(InputError, match="unknown algorithm 'rk4'"):
        load_scenario(rewritten(nominal_ssp, tmp_path / "rk4.ssp", {SSD: text}))
    assert load_scenario(nominal_ssp).algorithm == "gauss-seidel"



def test_unit_conversion_rules():
    """to_fmu_unit: factor and offset through the base units, plain SI names, refusals."""
    from aotv_cosim.model.ssp_units import to_fmu_unit

    m, km = ((0, 1, 0, 0, 0, 0, 0, 0), 1.0, 0.0), ((0, 1, 0, 0, 0, 0, 0, 0), 1000.0, 0.0)
    kelvin, celsius = ((0, 0, 0, 0, 1, 0, 0, 0), 1.0, 0.0), ((0, 0, 0, 0, 1, 0, 0, 0), 1.0, 273.15)

    def convert(v, u, f, ssp, fmu):
        return to_fmu_unit(v, u, f, ssp, fmu, file="x.ssp", entry="p")

    assert convert(2.5, "km", "m", {"km": km}, {"m": m}) == pytest.approx(2500.0)
    assert convert(2.5, "km", "m", {"km": km}, {}) == pytest.approx(2500.0)  # 'm' is a base unit
    assert convert(20.0, "degC", "K", {"degC": celsius}, {"K": kelvin}) == pytest.approx(293.15)
    assert convert(7.0, "m", "", {}, {}) == 7.0  # no unit declared by the FMU: SI taken as it is
    with pytest.raises(InputError, match="unit 'km' cannot be converted to the FMU's unit '\\(none\\)'"):
        convert(7.0, "km", "", {"km": km}, {})
    with pytest.raises(InputError, match="unit 'K' cannot be converted to the FMU's unit 'm'"):
        convert(7.0, "K", "m", {}, {})
    with pytest.raises(InputError, match="unit 'ft' is not defined"):
        convert(7.0, "ft", "m", {}, {})
