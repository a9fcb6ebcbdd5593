"""Bad input lines: a damaged member inside an FMU (a corrupt deflate stream) gives exit 2 and one
line naming the member and the damage, not exit 3 and zlib's raw message; a malformed --set names
the scenario; --resume never overwrites rows it cannot attribute to a campaign."""

import re
import zipfile

import pytest
from click.testing import CliRunner

from aotv_cosim.cli import main
from aotv_cosim.model.archives import extract_to
from aotv_cosim.errors import InputError
from tests.helpers import NOMINAL, SCENARIOS
from tests.model.archives import CORPUS

pytestmark = pytest.mark.usefixtures("crafted_archives")  # the wiring cases name them


@pytest.mark.integration
@pytest.mark.parametrize("case, member", [("wiring_fmu_corrupt_deflate_binary.json", "binaries/"),
                                          ("wiring_fmu_corrupt_deflate_description.json", "modelDescription.xml")])
def test_a_corrupt_deflate_stream_is_named(case, member):
    result = CliRunner().invoke(main, ["validate", str(CORPUS / case)])
    assert result.exit_code == 2
    line, = result.stderr.splitlines()
    assert f": member {member}" in line
    assert "is corrupt (invalid deflate data: invalid block type); give an intact" in line


def test_extracting_a_damaged_archive_leaves_nothing(tmp_path):
    archive = CORPUS / "fmus" / "bad_deflate_binary.fmu"
    assert zipfile.is_zipfile(archive)
    with pytest.raises(InputError, match=re.escape("cannot extract bad_deflate_binary.fmu: invalid deflate data: "
                                                   "invalid block type")):
        extract_to(archive, tmp_path / "x")
    assert list(tmp_path.iterdir()) == []


def test_a_malformed_set_names_the_scenario(tmp_path):
    result = CliRunner().invoke(main, ["run", str(NOMINAL), "--set", "h0=1", "--out", str(tmp_path / "o")])
    assert result.exit_code == 2
    assert result.stderr == (f"error: {NOMINAL}: --set: cannot read 'h0=1': no component.variable before an '='; "
                             "write component.variable=value\n")


@pytest.mark.integration
def test_resume_keeps_rows_of_an_unknown_campaign(tmp_path):
    (tmp_path / "rows.csv").write_text("run,status\n0,completed\n")
    result = CliRunner().invoke(main, ["montecarlo", str(SCENARIOS / "montecarlo_time_linear_density.json"),
                                       "--runs", "2", "--out", str(tmp_path), "--resume"])
    assert result.exit_code == 2
    assert result.stderr.startswith(f"error: {tmp_path / 'rows.csv'}: --resume: cannot resume: rows.csv is here but "
                                    "campaign.json")
    assert (tmp_path / "rows.csv").read_text() == "run,status\n0,completed\n"
