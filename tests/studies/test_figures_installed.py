"""The figure commands after a normal install: their scenarios ship in the package.

The default suite lays the package out as the wheel does (pyproject's force-include) and checks
that the figure modules find their scenarios there, from another folder; the slow tests install
a clone with pip into a virtual environment and draw the figures from a folder outside it, and
draw the seed-000 figures."""

import os
import shutil
import subprocess
import sys
import tomllib

import pytest
from click.testing import CliRunner

from aotv_cosim.cli import main

from tests.helpers import ROOT

pytestmark = pytest.mark.integration


def _wheel_layout(site):
    """Copy aotv_cosim and its force-included folders into `site` as the wheel places them."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    shutil.copytree(ROOT / "aotv_cosim", site / "aotv_cosim", ignore=shutil.ignore_patterns("__pycache__"))
    for source, target in config["tool"]["hatch"]["build"]["targets"]["wheel"]["force-include"].items():
        shutil.copytree(ROOT / source, site / target)


def test_installed_figure_modules_find_their_scenarios(tmp_path):
    site = tmp_path / "site"
    _wheel_layout(site)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    code = ("import aotv_cosim.studies.plane_change_plots as p, aotv_cosim.studies.shuttle_report as s, "
            "aotv_cosim.studies.shipped as sh;"
            "print(p.SCENARIO); print(s.SCENARIOS); print(sh.scenario('aotv_compare.json').is_file(),"
            " sh.scenario('entry_ideal_combined.json').is_file(), (s.SCENARIOS / 'shuttle_fl_400kft.json').is_file(),"
            " len(list(s.SCENARIOS.glob('aotv_table8_1_row*.json'))))")
    env = {**os.environ, "PYTHONPATH": str(site)}
    out = subprocess.run([sys.executable, "-c", code], cwd=elsewhere, env=env, capture_output=True, text=True,
                         check=True).stdout.splitlines()
    shipped = site / "aotv_cosim" / "scenarios"
    assert out == [str(shipped / "plane_change_mae_guided.json"), str(shipped), "True True True 11"]


@pytest.mark.slow
def test_figures_from_any_folder_after_pip_install(tmp_path):
    """pip install of a copy of the source tree (no editable link) into a venv, then figures seed001
    and seed003 from a folder outside it, the copy removed; 2-4 min (pip fetches hatchling)."""
    clone = tmp_path / "clone"
    shutil.copytree(ROOT, clone, ignore=shutil.ignore_patterns(".git", "results", "__pycache__", ".pytest_cache"))
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", str(venv)], check=True)
    subprocess.run([venv / "bin" / "python", "-m", "pip", "install", "-q", "--no-deps", str(clone)], check=True)
    shutil.rmtree(clone)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    for seed, expected in (("seed001", "fig3_19_guided_speed_end.png"), ("seed003", "seed003_saturation.png")):
        done = subprocess.run([venv / "bin" / "aotv-cosim", "figures", seed, "--out", "figs"], cwd=elsewhere,
                              env=env, capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        assert (elsewhere / "figs" / expected).stat().st_size > 10_000


@pytest.mark.slow
def test_figures_seed000(tmp_path):
    """The laws' trajectories (nominal and dispersed) and the Table 8.1 comparison: 11 rows x 4
    quantities, every one within the tolerances of the row scenarios (about a minute)."""
    result = CliRunner().invoke(main, ["figures", "seed000", "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    table = [line for line in result.output.splitlines() if line.endswith(("pass", "FAIL"))]
    assert len(table) == 44 and all(line.endswith("pass") for line in table)
    for name in ("laws/comparison.png", "dispersed/comparison.png", "table8_1.png"):
        assert (tmp_path / name).stat().st_size > 20_000
    lines = (tmp_path / "table8_1.csv").read_text().splitlines()
    assert lines[0] == "row,K_1_m,quantity,unit,thesis,measured,rel_error,passed" and len(lines) == 45


@pytest.mark.slow
def test_figures_seed002_without_a_run_dir(tmp_path):
    """Without RUN_DIR the ideal combined case is run first, then Figs. 1-6 drawn (about a minute)."""
    result = CliRunner().invoke(main, ["figures", "seed002", "--out", str(tmp_path)])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "run" / "timeseries.csv").is_file()
    assert sorted(p.name for p in tmp_path.glob("fig*.png")) == [
        "fig1_ground_track.png", "fig2_errors.png", "fig3_alpha.png", "fig4_bank.png", "fig5_altitude.png",
        "fig6_drag.png"]
