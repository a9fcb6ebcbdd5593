"""What many test modules share: the repository's paths, JSON files written from dicts, the CLI
invoked in-process or as a process of its own, the short nominal and the two-FMU relay scenarios,
the check of a whole time series and what a saved figure shows."""

import json
import os
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import pytest
from click.testing import CliRunner

from aotv_cosim.cli import main

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / "scenarios"
NOMINAL = SCENARIOS / "aotv_time_linear_nominal.json"
WIRING = SCENARIOS / "systems" / "aotv_time_linear.json"

STEP = 0.01
"""Communication step (s) of the relay scenario and of the interrupt tests' scenarios."""


def write_json(path: Path, data) -> Path:
    path.write_text(json.dumps(data, indent=2))
    return path


def cli(*args):
    """The click Result of `aotv-cosim ARGS` (each turned to str); only SystemExit may end it."""
    result = CliRunner().invoke(main, [str(a) for a in args])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    return result


def invoke(*args) -> tuple:
    """(exit status, printed text) of `aotv-cosim ARGS`; the text holds stdout and stderr."""
    result = CliRunner().invoke(main, [str(a) for a in args])
    return result.exit_code, result.output


def error_lines(text: str) -> list:
    return [line for line in text.splitlines() if line.startswith("error:")]


def one_line(args, *fragments, cwd=None) -> str:
    """Invoke the CLI; assert exit 2, one stderr line starting 'error: ' holding every fragment."""
    result = cli(*args)
    lines = result.stderr.strip().splitlines()
    assert result.exit_code == 2, (result.exit_code, result.output, result.stderr)
    assert len(lines) == 1 and lines[0].startswith("error: "), lines
    assert "Traceback" not in result.output + result.stderr
    for fragment in fragments:
        assert fragment in lines[0], lines[0]
    assert "; " in lines[0], lines[0]
    return lines[0]


def command(*args) -> list:
    """argv of `python -m aotv_cosim ARGS` (each turned to str) in this interpreter."""
    return [sys.executable, "-m", "aotv_cosim", *map(str, args)]


def package_env(**extra) -> dict:
    """This process's environment, in which a subprocess imports the package of this tree."""
    return dict(os.environ, PYTHONPATH=str(ROOT), **extra)


def run_process(*args, timeout: float = 300) -> subprocess.CompletedProcess:
    """`aotv-cosim ARGS` run to its end in a process of its own (text output captured)."""
    return subprocess.run(command(*args), cwd=ROOT, env=package_env(), capture_output=True, text=True,
                          timeout=timeout)


def start_process(*args, **popen) -> subprocess.Popen:
    """`aotv-cosim ARGS` started in a process of its own, stdout and stderr piped as text."""
    return subprocess.Popen(command(*args), cwd=ROOT, env=package_env(), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, **popen)


def short_nominal(folder: Path, stop: float, name: str = "short.json") -> Path:
    """The nominal seed-000 scenario cut to `stop` (s), without expectations or plots."""
    doc = json.loads(NOMINAL.read_text())
    doc.update(system=str(WIRING), stop=stop)
    for key in ("$schema", "expectations", "plots"):
        doc.pop(key, None)
    return write_json(folder / name, doc)


def relay_scenario(folder: Path, stop: float, name: str = "relay.json") -> Path:
    """Two FMUs (a FaultInjector passing u = 0.5 -> LiftActuator) stepped by STEP until `stop` (s);
    1e5 s is 10^7 steps, minutes: far longer than any test waits."""
    wiring = write_json(folder / "wiring.json", {
        "components": {"relay": {"fmu": "FaultInjector", "parameters": {"u": 0.5}},
                       "actuator": {"fmu": "LiftActuator"}},
        "connections": ["relay.y -> actuator.command"]})
    return write_json(folder / name, {"system": str(wiring), "stop": stop, "step": STEP})


def wait_for_rows(part: Path, process, timeout: float = 120.0) -> None:
    """Wait until the run `process` has flushed rows to `part` (timeseries.csv.part: its first
    chunk), so it holds its output folder and is stepping."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if part.is_file() and part.read_text().count("\n") > 1:
            return
        assert process.poll() is None, process.communicate()
        time.sleep(0.05)
    pytest.fail("no rows written in time")


def check_whole_rows(out: Path) -> list:
    """Every line complete and parseable, one increasing time k * STEP per row; returns the rows."""
    assert not list(out.glob("*.part"))
    text = (out / "timeseries.csv").read_text()
    assert text.endswith("\n")
    header, *lines = text.splitlines()
    width = len(header.split(","))
    rows = [[float(x) for x in line.split(",")] for line in lines]
    assert all(len(r) == width for r in rows)
    assert [r[0] for r in rows] == pytest.approx([k * STEP for k in range(len(rows))], abs=1e-9)
    return rows


@dataclass(frozen=True)
class Panel:
    """What one drawn Axes of a figure shows: its texts, its line labels (matplotlib's `_childN`
    for unlabelled ones), the entries of its legend, how many collections (scatter points) and
    patches (histogram bars, shaded bands) it holds, its axis scales, y limits and x tick labels."""

    title: str
    xlabel: str
    ylabel: str
    lines: tuple
    legend: tuple
    collections: int
    patches: int
    xscale: str = "linear"
    yscale: str = "linear"
    ylim: tuple = ()
    xticklabels: tuple = ()


@dataclass(frozen=True)
class Drawing:
    """What a saved figure shows: its suptitle ('' without one) and its drawn Axes, in order
    (Axes switched off, the empty cells of a grid, are left out)."""

    title: str
    panels: tuple


def drawing(fig) -> Drawing:
    """The Drawing of the matplotlib Figure `fig` as it stands."""
    panels = tuple(Panel(ax.get_title(), ax.get_xlabel(), ax.get_ylabel(),
                         tuple(line.get_label() for line in ax.get_lines()),
                         tuple(text.get_text() for text in ax.get_legend().get_texts()) if ax.get_legend() else (),
                         len(ax.collections), len(ax.patches), ax.get_xscale(), ax.get_yscale(), ax.get_ylim(),
                         tuple(t.get_text() for t in ax.get_xticklabels()))
                   for ax in fig.axes if ax.axison)
    return Drawing(fig.get_suptitle(), panels)
