"""docs/writing-a-guidance-law.md runs as written: every code block, in order, in a folder outside
the repository (files written, Python and shell blocks run), the benchmark with a small N."""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from aotv_cosim.campaigns.benchmark import stored_rows_dir
from tests.helpers import ROOT

TUTORIAL = ROOT / "docs" / "writing-a-guidance-law.md"
BLOCK = re.compile(r"^```(\w+)(?: file=(\S+))?\n(.*?)^```$", re.S | re.M)
SMALL = {"--runs 200": "--runs 2", "--workers 2": "--workers 1",
         "benchmark benchmark_seed000 ": "benchmark benchmark_seed000/time_linear.json "}
"""What the test changes in the shell blocks, to take seconds: the benchmark's N, and one shipped
law of the set (a single scenario file is a set too) instead of eight; the flow is the same."""


def blocks():
    """(language, file name or None, text) of every fenced block of the tutorial, in order."""
    return [(m.group(1), m.group(2), m.group(3)) for m in BLOCK.finditer(TUTORIAL.read_text())]


def test_the_tutorial_has_each_step():
    kinds = [(language, name) for language, name, _ in blocks()]
    assert ("python", "ApogeeFeedback.py") in kinds and ("json", "pass.json") in kinds
    shell = "\n".join(text for language, _, text in blocks() if language == "sh")
    for command in ("build-fmus ApogeeFeedback.py", "run pass.json", "pytest", "benchmark benchmark_seed000 --law"):
        assert command in shell


@pytest.mark.integration
def test_every_block_of_the_tutorial_runs(tmp_path):
    env = {**os.environ, "PATH": os.pathsep.join([str(Path(sys.executable).parent), os.environ["PATH"]])}
    for language, name, text in blocks():
        if name:
            (tmp_path / name).write_text(text)
        elif language == "python":
            done = subprocess.run([sys.executable, "-c", text], cwd=tmp_path, env=env, capture_output=True, text=True)
            assert done.returncode == 0, text + done.stdout + done.stderr
        elif language == "sh":
            for line in filter(None, text.splitlines()):
                for long, short in SMALL.items():
                    line = line.replace(long, short)
                done = subprocess.run(line, shell=True, cwd=tmp_path, env=env, capture_output=True, text=True)
                assert done.returncode == 0, line + "\n" + done.stdout + done.stderr
    assert not (ROOT / "ApogeeFeedback.py").exists()
    scorecard = (tmp_path / "results" / "bench" / "scorecard.csv").read_text()
    assert [line.split(",")[:2] for line in scorecard.splitlines()[1:]] == [["time_linear", "2"], ["aotv_apogee", "2"]]
    assert "outcome" in (tmp_path / "results" / "pass" / "summary.json").read_text()
    assert stored_rows_dir().is_dir()
