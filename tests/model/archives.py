"""Files for the bad-input tests: the corpus of malformed documents and crafted FMU archives, and
SSP archives exported from the nominal scenario and rewritten member by member."""

import zipfile

from aotv_cosim.simulation.loading import load_scenario
from aotv_cosim.ssp.export import export_ssp
from tests.helpers import NOMINAL, ROOT

CORPUS = ROOT / "tests" / "data" / "corpus"
"""The input-validation catalogue: index.json and the malformed files it lists (their relative
paths to the shipped scenarios count the folders up to the repository)."""

SSD = "SystemStructure.ssd"


def export_nominal(tmp_path_factory):
    """The nominal seed-000 scenario exported as an .ssp archive in a fresh folder."""
    return export_ssp(load_scenario(NOMINAL), tmp_path_factory.mktemp("ssp") / "nominal.ssp")


def rewritten(archive, out, replace=None, add=None):
    """A copy of the zip `archive` with members replaced (text or bytes; None drops one) and added."""
    replace = replace or {}
    with zipfile.ZipFile(archive) as src, zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as dst:
        for info in src.infolist():
            data = replace.get(info.filename, src.read(info.filename))
            if data is not None:
                dst.writestr(info.filename, data)
        for name, data in (add or {}).items():
            dst.writestr(name, data)
    return out


def ssd_text(ssp):
    with zipfile.ZipFile(ssp) as archive:
        return archive.read(SSD).decode()
