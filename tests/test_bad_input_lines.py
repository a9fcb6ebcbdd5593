"""A damaged member inside an FMU (a corrupt deflate stream) is bad input: exit 2 and one line
naming the member and the damage, not exit 3 and zlib's raw message."""

import zipfile

import pytest
from click.testing import CliRunner

from aotv_cosim.cli import main
from aotv_cosim.engine.archives import extract_to
from aotv_cosim.engine.errors import InputError
from test_corpus import CORPUS, crafted_archives  # noqa: F401 (writes the crafted archives)


@pytest.mark.parametrize("case, member", [("wiring_fmu_corrupt_deflate_binary.json", "binaries/"),
                                          ("wiring_fmu_corrupt_deflate_description.json", "modelDescription.xml")])
def test_a_corrupt_deflate_stream_is_named(case, member):
    result = CliRunner().invoke(main, ["validate", str(CORPUS / case)])
    assert result.exit_code == 2
    line, = result.stderr.splitlines()
    assert f": member {member}" in line and "is corrupt (invalid deflate data: invalid block type); give an intact" in line


def test_extracting_a_damaged_archive_leaves_nothing(tmp_path):
    archive = CORPUS / "fmus" / "bad_deflate_binary.fmu"
    assert zipfile.is_zipfile(archive)
    with pytest.raises(InputError, match="cannot extract bad_deflate_binary.fmu: invalid deflate data: invalid block type"):
        extract_to(archive, tmp_path / "x")
    assert list(tmp_path.iterdir()) == []
