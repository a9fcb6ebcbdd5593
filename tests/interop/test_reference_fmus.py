"""The public Modelica Reference FMUs in `aotv-cosim run` on their default experiment, every output
compared with fmpy.simulate_fmu to the bit, as FMI 2.0 and as FMI 3.0 builds. The suite cannot
download them: build them by hand and point AOTV_REFERENCE_FMUS (FMI 2.0) and AOTV_REFERENCE_FMUS3
(FMI 3.0) at the folders of .fmu files, e.g.

    git clone https://github.com/modelica/Reference-FMUs && cd Reference-FMUs
    cmake -B build2 -DFMI_VERSION=2 -DCMAKE_BUILD_TYPE=Release && cmake --build build2
    cmake -B build3 -DFMI_VERSION=3 -DCMAKE_BUILD_TYPE=Release && cmake --build build3
    AOTV_REFERENCE_FMUS=$PWD/build2/fmus AOTV_REFERENCE_FMUS3=$PWD/build3/fmus \
        python -m pytest tests/interop/test_reference_fmus.py

(gcc 12 and later: add -DCMAKE_C_FLAGS=-Wno-error=stringop-truncation to the FMI 3.0 configure,
whose Resource model.c otherwise stops the build.) Without a folder its tests are skipped.
"""

import json
import os
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from aotv_cosim.cli import main

FOLDERS = {"2.0": os.environ.get("AOTV_REFERENCE_FMUS"), "3.0": os.environ.get("AOTV_REFERENCE_FMUS3")}
pytestmark = pytest.mark.integration

NAMES = ["BouncingBall", "Dahlquist", "VanDerPol", "Stair", "Feedthrough", "Resource"]

INPUTS = {"Feedthrough": {"Float64_continuous_input": 1.5, "Float64_discrete_input": 2.5, "Int32_input": 3,
                          "Boolean_input": True, "String_input": "hello", "Enumeration_input": "Option 2",
                          "Float64_tunable_parameter": 0.25, "Float64_fixed_parameter": 0.5}}
"""Values given to the FMUs' inputs and parameters (the same to FMPy, an Enumeration by integer)."""

INPUTS3 = {"Feedthrough": {**INPUTS["Feedthrough"], "Float32_continuous_input": 0.1, "Float32_discrete_input": -2.75,
                           "Int8_input": -128, "UInt8_input": 255, "Int16_input": -32768, "UInt16_input": 65535,
                           "Int32_input": -2147483648, "UInt32_input": 4294967295, "Int64_input": -(2 ** 53),
                           "UInt64_input": 2 ** 53, "Binary_input": "00ff10"}}
"""The FMI 3.0 Feedthrough's inputs, every type at an end of its range (the 64-bit ones at
+-2^53, what the master's float64 buffer holds exactly), a Float32 that is not a float64's value."""


def folder(version):
    found = FOLDERS[version]
    if not found:
        pytest.skip(f"{'AOTV_REFERENCE_FMUS3' if version == '3.0' else 'AOTV_REFERENCE_FMUS'} names no folder "
                    f"of Reference FMUs built for FMI {version}")
    return Path(found)


def fmpy_value(md, name, value):
    """A wiring value as fmpy.simulate_fmu takes it: an Enumeration by integer (a Binary as hexadecimal
    text, as the wiring gives it)."""
    var = next(v for v in md.modelVariables if v.name == name)
    if var.type == "Enumeration":
        return next(int(item.value) for item in var.declaredType.items if item.name == value)
    return value


@pytest.mark.parametrize("version", ["2.0", "3.0"])
@pytest.mark.parametrize("name", NAMES)
def test_a_reference_fmu_agrees_with_fmpy(name, version, tmp_path):
    import fmpy

    fmu = folder(version) / f"{name}.fmu"
    md = fmpy.read_model_description(str(fmu))
    assert md.fmiVersion == version
    experiment = md.defaultExperiment
    values = (INPUTS3 if version == "3.0" else INPUTS).get(name, {})
    scenario = {"system": "w.json"}
    if experiment.stepSize is None:  # FMPy's default output interval then
        interval = (float(experiment.stopTime) - float(experiment.startTime or 0)) / 500
        scenario["step"] = interval
    else:
        interval = float(experiment.stepSize)  # FMPy would double it past 1000 points
    (tmp_path / "w.json").write_text(json.dumps({"components": {"m": {"fmu": str(fmu), "parameters": values}},
                                                 "connections": []}))
    (tmp_path / "s.json").write_text(json.dumps(scenario))
    result = CliRunner().invoke(main, ["run", str(tmp_path / "s.json"), "--out", str(tmp_path / "out"), "--no-plots"])
    assert result.exit_code == 0, result.output + result.stderr
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["status"] == ("terminated" if name == "Stair" else "completed") and not summary["warnings"]
    ours = pd.read_csv(tmp_path / "out" / "timeseries.csv", keep_default_na=False)
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    start_values = {k: fmpy_value(md, k, v) for k, v in values.items()}
    reference = fmpy.simulate_fmu(str(fmu), output=outputs, output_interval=interval, start_values=start_values)
    assert np.array_equal(ours["time"].to_numpy(), reference["time"])
    for output in outputs:
        if output in reference.dtype.names:
            assert np.array_equal(ours[f"m.{output}"].to_numpy().astype(reference[output].dtype),
                                  reference[output]), output
        else:  # FMPy records no String or Binary output: they repeat their input
            assert set(ours[f"m.{output}"].astype(str)) == {values[output.replace("_output", "_input")]}, output


@pytest.mark.parametrize("name, feature", [("Clocks", "for scheduled execution only"),
                                           ("StateSpace", "array variables (A, B, C, ...): FMI 3.0 arrays")])
def test_what_the_master_does_not_run_is_refused_in_one_line(name, feature, tmp_path):
    """The FMI 3.0 Clocks (scheduled execution) and StateSpace (arrays) are refused when the wiring
    is loaded: one line naming the feature, exit 2."""
    from tests.helpers import one_line

    wiring = tmp_path / "w.json"
    wiring.write_text(json.dumps({"components": {"m": {"fmu": str(folder("3.0") / f"{name}.fmu")}},
                                  "connections": []}))
    one_line(["validate", wiring], f"{name}.fmu", feature)
    (tmp_path / "s.json").write_text(json.dumps({"system": "w.json", "stop": 1.0, "step": 0.5}))
    one_line(["run", tmp_path / "s.json", "--out", tmp_path / "out"], feature)
