"""docs/examples/benchmark_a_bank_law.ipynb runs as written (issue 36 item 7): a Jupyter kernel
executes every cell, in a copy of the examples folder (the user's law file and wiring beside the
notebook), with its small N; the comparison figure is drawn."""

import shutil

import nbformat
import pytest
from nbclient import NotebookClient

from tests.helpers import ROOT

pytestmark = pytest.mark.integration

EXAMPLES = ROOT / "docs" / "examples"
NOTEBOOK = "benchmark_a_bank_law.ipynb"


def test_the_example_notebook_benchmarks_the_users_law_and_draws_the_comparison(tmp_path, monkeypatch):
    folder = tmp_path / "examples"
    shutil.copytree(EXAMPLES, folder)
    monkeypatch.setenv("PYTHONPATH", str(ROOT))  # the kernel imports this tree's package
    nb = nbformat.read(folder / NOTEBOOK, as_version=4)
    for cell in nb.cells:
        if cell.cell_type == "code":
            cell.outputs = []  # nothing kept from the committed run
    NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(folder)}}).execute()
    outputs = [o for cell in nb.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    texts = "\n".join(o.get("text", "") + o.get("data", {}).get("text/plain", "") for o in outputs)
    assert "'wiring')]" in texts and "bisection_bank" in texts and "npc_bank" in texts
    assert "| `bank.saturation_time` | output | s |" in "".join(o.get("data", {}).get("text/markdown", "")
                                                             for o in outputs)
    assert any("image/png" in o.get("data", {}) for o in outputs)  # the comparison figure
    assert sorted(p.name for p in folder.iterdir()) == sorted(p.name for p in EXAMPLES.iterdir())  # wrote nothing
