"""Safety of inputs: archives whose members would land outside the extraction folder are refused,
and paths in wiring and scenario files resolve relative to the file, not the working folder."""

import shutil
import zipfile

import pytest

from aotv_cosim.fmu import build as fmu_build
from aotv_cosim.errors import InputError
from aotv_cosim.simulation.loading import load_scenario
from aotv_cosim.model.fmu_file import check_archive
from tests.helpers import write_json

ESCAPING = ["/etc/aotv_evil", "../evil.txt", "resources/../../evil.txt", "C:/evil.txt",
            "..\\evil.txt", "resources\\..\\..\\evil.txt"]


def _zip(path, members):
    with zipfile.ZipFile(path, "w") as archive:
        for name in members:
            archive.writestr(zipfile.ZipInfo(name), "x")
    return path


@pytest.mark.parametrize("suffix", [".fmu", ".ssp"])
@pytest.mark.parametrize("member", ESCAPING)
def test_archive_member_escaping_is_refused(tmp_path, suffix, member):
    archive = _zip(tmp_path / f"crafted{suffix}", ["modelDescription.xml", member])
    with pytest.raises(InputError, match="escapes the extraction folder") as caught:
        check_archive(archive, file="system.json", entry="components.x.fmu")
    assert str(caught.value).startswith("system.json: components.x.fmu: member ")


@pytest.mark.integration
def test_ordinary_archives_pass():
    check_archive(fmu_build.ensure_fmu("Atmosphere"))
    check_archive(fmu_build.ensure_fmu("FaultInjector"))


@pytest.mark.integration
def test_paths_resolve_relative_to_the_file_not_the_working_folder(tmp_path, monkeypatch):
    """scenario scn/s.json -> ../sys/wiring.json -> fmus/Atmosphere.fmu, run from another folder."""
    fmus = tmp_path / "sys" / "fmus"
    fmus.mkdir(parents=True)
    shutil.copy(fmu_build.ensure_fmu("Atmosphere"), fmus / "Atmosphere.fmu")
    write_json(tmp_path / "sys" / "wiring.json", {
        "components": {"air": {"fmu": "fmus/Atmosphere.fmu", "parameters": {"h": 0.0}}},
        "connections": []})
    (tmp_path / "scn").mkdir()
    scenario = write_json(tmp_path / "scn" / "s.json", {"system": "../sys/wiring.json", "stop": 1, "step": 0.5})
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    loaded = load_scenario("../scn/s.json")
    assert loaded.path == scenario
    assert loaded.system.path == tmp_path / "sys" / "wiring.json"
    assert loaded.system.components["air"].fmu.path == fmus / "Atmosphere.fmu"
