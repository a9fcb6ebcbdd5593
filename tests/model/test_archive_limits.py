"""Resource limits: the duplicate-key check is linear, archives are checked
against size limits before anything is extracted, and a refused archive leaves nothing in the
cache."""

import hashlib
import re
import time
import zipfile

import pytest

from aotv_cosim.model import archives
from aotv_cosim.fmu import build as fmu_build
from aotv_cosim.model.documents import strict_json
from aotv_cosim.errors import InputError
from aotv_cosim.model.ssp_load import extract, read_ssp
from aotv_cosim.model.fmu_file import check_archive
from tests.helpers import one_line
from tests.model.archives import SSD, rewritten


def test_duplicate_key_check_is_linear():
    """200,000 distinct keys parse in well under 20 s (the quadratic check took 56 s for 20,000,
    so about 5,600 s for these); a repeated key among them is still found and named."""
    keys = [f"k{i}" for i in range(200_000)]
    text = "{" + ",".join(f'"{k}": {i}' for i, k in enumerate(keys)) + "}"
    started = time.process_time()
    assert len(strict_json(text)) == len(keys)
    assert time.process_time() - started < 20.0
    with pytest.raises(ValueError, match="duplicate key 'k123'"):
        strict_json(text[:-1] + ', "k123": 0}')


def _cache_entries(folder):
    return sorted(p.name for p in folder.iterdir()) if folder.is_dir() else []


def test_compressed_zeros_are_refused_before_extraction(tmp_path):
    """A 64 MiB member of zeros compresses to about 64 kB (ratio about 1000): refused from the
    zip directory, so nothing is written to the cache."""
    bomb = tmp_path / "bomb.ssp"
    with zipfile.ZipFile(bomb, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr(SSD, "<x/>")
        with archive.open("resources/padding.bin", "w", force_zip64=True) as member:
            for _ in range(64):
                member.write(bytes(2**20))
    assert bomb.stat().st_size < 2**20
    before = _cache_entries(fmu_build.cache_dir() / "ssp")
    with pytest.raises(InputError, match=r"inflates .* \(more than 200x\)"):
        extract(bomb)
    assert _cache_entries(fmu_build.cache_dir() / "ssp") == before
    one_line(["validate", bomb], "bomb.ssp", "inflates")


def test_total_size_and_member_count_limits(tmp_path, monkeypatch):
    archive = tmp_path / "many.fmu"
    with zipfile.ZipFile(archive, "w") as z:
        for k in range(5):
            z.writestr(f"resources/{k}.txt", "x" * 1000)
    check_archive(archive)
    monkeypatch.setattr(archives, "MAX_TOTAL_BYTES", 4000)
    with pytest.raises(InputError, match="5000 bytes uncompressed, more than 4000"):
        check_archive(archive, file="w.json", entry="components.a.fmu")
    monkeypatch.setattr(archives, "MAX_MEMBERS", 4)
    with pytest.raises(InputError, match="5 members, more than 4"):
        check_archive(archive)


@pytest.mark.integration
def test_a_refused_ssp_leaves_nothing_in_the_cache(nominal_ssp, tmp_path):
    """An archive refused after extraction (here: an SSD that violates the schema) has its
    extracted folder removed; an accepted one stays cached."""
    folder = extract(nominal_ssp)
    assert folder.is_dir()
    read_ssp(nominal_ssp)
    assert folder.is_dir()
    bad = rewritten(nominal_ssp, tmp_path / "bad.ssp", {SSD: "<ssd:SystemStructureDescription "
                                                            "xmlns:ssd='http://ssp-standard.org/SSP1/"
                                                            "SystemStructureDescription'/>"})
    with pytest.raises(InputError, match=re.escape("violates the SSP 1.0 schema")):
        read_ssp(bad)
    digest = hashlib.sha256(bad.read_bytes()).hexdigest()[:16]  # the cache folder's name
    assert digest not in _cache_entries(fmu_build.cache_dir() / "ssp")


def test_a_failed_extraction_removes_its_staging_folder(tmp_path):
    """A member whose data fails its CRC check stops the extraction: the partial folder goes."""
    good = tmp_path / "good.zip"
    with zipfile.ZipFile(good, "w", zipfile.ZIP_STORED) as z:
        z.writestr("a.txt", "hello world " * 100)
    data = bytearray(good.read_bytes())
    data[data.index(b"hello") + 5] ^= 0xFF
    (tmp_path / "bad.zip").write_bytes(bytes(data))
    target = tmp_path / "cache" / "x"
    with pytest.raises(InputError, match=re.escape("cannot extract bad.zip")):
        archives.extract_to(tmp_path / "bad.zip", target)
    assert _cache_entries(tmp_path / "cache") == []
