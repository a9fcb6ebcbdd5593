"""This package's FMUs refuse what the Modelica Reference FMUs refuse, in this master too (its C
path: `--fmi-calls c`): an FMU whose modelDescription GUID was changed fails at instantiation
with the FMU's own message, and one whose modelDescription declares a Real input an Enumeration
fails at the first fmi2SetInteger. FMPy and the C hosts: tests/fmus/test_fmi3_export.py and
tests/fmus/test_c_host_fmi3.py. (The direct in-process path does not go through the wrapper: it
reads the same resources/aotv_cosim_guid.txt, tests/simulation/test_direct_calls.py.)
"""

import json
import re
import zipfile

import pytest

from aotv_cosim.fmu import build as fmu_build
from aotv_cosim.fmu import native
from tests.fmus.test_fmi3_export import as_enumeration
from tests.helpers import cli

pytestmark = [
    pytest.mark.integration,
    pytest.mark.skipif(native.wrapper() != "lean", reason="the stock pythonfmu wrapper is not strict"),
]


def with_changed_guid(fmu, out):
    with zipfile.ZipFile(fmu) as archive:
        members = {info.filename: archive.read(info) for info in archive.infolist()}
    xml = members["modelDescription.xml"].decode()
    guid = re.search(r'guid="\{([^}]*)\}"', xml).group(1)
    members["modelDescription.xml"] = xml.replace(guid, guid[:-1] + ("0" if guid[-1] != "0" else "1")).encode()
    with zipfile.ZipFile(out, "w") as archive:
        for name, data in members.items():
            archive.writestr(name, data)
    return out


def run_alone(fmu, value, folder):
    """(exit status, summary) of `aotv-cosim run` of the FMU alone with h = value, C path."""
    (folder / "wiring.json").write_text(json.dumps({"components": {"a": {"fmu": fmu.name, "parameters": {"h": value}}},
                                                    "connections": []}))
    (folder / "scenario.json").write_text(json.dumps({"system": "wiring.json", "stop": 1.0, "step": 0.1}))
    result = cli("run", folder / "scenario.json", "--fmi-calls", "c", "--no-plots", "--out", folder / "out")
    return result.exit_code, json.loads((folder / "out" / "summary.json").read_text())


def test_master_c_path_refuses_an_fmu_with_a_changed_guid(tmp_path):
    fmu = with_changed_guid(fmu_build.ensure_fmu("Atmosphere"), tmp_path / "guid.fmu")
    status, summary = run_alone(fmu, 1000.0, tmp_path)
    assert status == 1 and summary["status"] == "failed"
    assert "instantiation refused: the GUID given" in json.dumps(summary["error"])


def test_master_c_path_refuses_a_real_input_declared_as_enumeration(tmp_path):
    fmu = as_enumeration(fmu_build.ensure_fmu("Atmosphere"), tmp_path / "enum.fmu")
    status, summary = run_alone(fmu, 1, tmp_path)
    assert status == 1 and summary["status"] == "failed"
    assert "[setInteger] refused: value reference 11 is a variable of type Real" in json.dumps(summary["error"])
