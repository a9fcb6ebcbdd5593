"""The `figures` command: the report figures of a seed drawn as PNG files."""

import pytest

from tests.helpers import invoke


@pytest.mark.integration
def test_figures_seed001_draws_the_report_figures(tmp_path, drawn):
    """`aotv-cosim figures seed001` writes the Figs. 3.4-3.19 counterparts as PNG files: each one
    panel titled with its figure number, the open-loop ones against the heading, the guided ones
    against time with the optimum as a second curve."""
    code, text = invoke("figures", "seed001", "--out", tmp_path)
    assert code == 0, text
    written = sorted(p.name for p in tmp_path.glob("*.png"))
    assert written and all((tmp_path / name).stat().st_size > 1000 for name in written)
    assert sorted(line.rsplit("/", 1)[-1] for line in text.split()) == written
    assert len(written) == 16  # Figs. 3.4-3.19
    for name in written:
        panel, = drawn[(tmp_path / name).resolve()].panels
        assert panel.title.startswith(f"Fig. 3.{int(name[5:7])}: "), (name, panel.title)
        assert panel.ylabel
        if "_open_loop_" in name:
            assert panel.xlabel == "heading psi [deg]" and "composite" in panel.lines
        else:
            assert panel.xlabel == "time [s]" and panel.lines[1] == "optimal"


def test_figures_seed002_needs_a_finished_run(tmp_path):
    code, text = invoke("figures", "seed002", tmp_path / "missing")
    assert code == 2 and "does not exist" in text
