"""The public Modelica Reference FMUs (FMI 2.0) in `aotv-cosim run` on their default experiment,
every output compared with fmpy.simulate_fmu. The suite cannot download them: build them by hand
and point AOTV_REFERENCE_FMUS at the folder of .fmu files, e.g.

    git clone https://github.com/modelica/Reference-FMUs && cd Reference-FMUs
    cmake -B build -DFMI_VERSION=2 -DCMAKE_BUILD_TYPE=Release && cmake --build build
    AOTV_REFERENCE_FMUS=$PWD/build/fmus python -m pytest tests/test_reference_fmus.py

Without it the tests are skipped.
"""

import json
import os
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from aotv_cosim.cli import main

FOLDER = os.environ.get("AOTV_REFERENCE_FMUS")
pytestmark = [pytest.mark.integration, pytest.mark.skipif(not FOLDER, reason="AOTV_REFERENCE_FMUS names no folder of built Reference FMUs")]

INPUTS = {"Feedthrough": {"Float64_continuous_input": 1.5, "Float64_discrete_input": 2.5, "Int32_input": 3,
                          "Boolean_input": True, "String_input": "hello", "Enumeration_input": "Option 2",
                          "Float64_tunable_parameter": 0.25, "Float64_fixed_parameter": 0.5}}
"""Values given to the FMUs' inputs and parameters (the same to FMPy, an Enumeration by integer)."""


@pytest.mark.parametrize("name", ["BouncingBall", "Dahlquist", "VanDerPol", "Stair", "Feedthrough", "Resource"])
def test_a_reference_fmu_agrees_with_fmpy(name, tmp_path):
    import fmpy

    fmu = Path(FOLDER) / f"{name}.fmu"
    md = fmpy.read_model_description(str(fmu))
    experiment = md.defaultExperiment
    values = INPUTS.get(name, {})
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
    start_values = {k: 2 if k == "Enumeration_input" else v for k, v in values.items()}
    reference = fmpy.simulate_fmu(str(fmu), output=outputs, output_interval=interval, start_values=start_values)
    assert np.array_equal(ours["time"].to_numpy(), reference["time"])
    for output in outputs:
        if output in reference.dtype.names:
            assert np.array_equal(ours[f"m.{output}"].to_numpy().astype(reference[output].dtype),
                                  reference[output]), output
        else:  # FMPy records no String output
            assert set(ours[f"m.{output}"]) == {values["String_input"]}
