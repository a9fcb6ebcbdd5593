"""Interrupts at many moments: every SIGINT/SIGTERM that reaches a run ends it with exit 130/143,
whole rows (every CSV line complete, one time per row, in order) and summary.json 'interrupted'.

Two sources of signals, 64 in all (53 of them in the tests marked slow):
- the Signaller test FMU sends the signal to its own process from inside its do_step at a
  chosen step (first, last, both sides of a chunk flush, others): the signal lands in FMU code,
  and the run must stop before the very next step (the latency of item 3);
- a timer thread sends it at random moments of the run (instantiation, stepping, the writer's
  flushes, closing). A signal that arrives outside the command (before its handler is installed
  or after it is restored) is caught by this test's own handler and that run must be completed.
The runs are in-process through the CLI (`CliRunner`), which exercises the same handler, loop
and writers as a subprocess; tests/test_interrupt.py sends real signals to real processes.
"""

import json
import os
import random
import signal
import threading
import time
from typing import ClassVar

import pytest
from click.testing import CliRunner

from aotv_cosim.simulation import interrupts
from aotv_cosim.cli import main
from aotv_cosim.simulation.rows import CHUNK
from tests.helpers import STEP, check_whole_rows, run_process, write_json
from tests.helper_fmus.signaller import build_signaller

N_STEPS = 2500  # 2 flushes of CHUNK rows plus the last partial chunk


@pytest.fixture(scope="module")
def signaller(tmp_path_factory):
    return build_signaller(tmp_path_factory.mktemp("signaller"))


def _scenario(tmp_path, fmu, n_steps=N_STEPS, **parameters):
    wiring = write_json(tmp_path / "wiring.json", {
        "components": {"sig": {"fmu": str(fmu), "parameters": parameters},
                       "relay": {"fmu": "FaultInjector"}, "actuator": {"fmu": "LiftActuator"}},
        "connections": ["sig.y -> relay.u", "relay.y -> actuator.command"]})
    return write_json(tmp_path / "scenario.json", {"system": str(wiring), "stop": n_steps * STEP, "step": STEP})


class _Strays:
    """Replaces the default SIGINT/SIGTERM actions during the test: counts signals that reach
    the process while no run is listening, instead of ending pytest."""

    def __init__(self):
        self.count = 0

    def __call__(self, signum, frame):
        self.count += 1

    def __enter__(self):
        self.previous = {n: signal.signal(n, self) for n in (signal.SIGINT, signal.SIGTERM)}
        return self

    def __exit__(self, *exc):
        for n, h in self.previous.items():
            signal.signal(n, h)


def _invoke(scenario, out):
    return CliRunner().invoke(main, ["run", str(scenario), "--out", str(out), "--no-plots"])


def _interrupted(result, out, signum):
    assert result.exit_code == 128 + signum, (result.output, result.exception)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "interrupted", summary
    assert summary["stop_reason"] == f"interrupted by {signal.Signals(signum).name}"
    rows = check_whole_rows(out)
    assert summary["end_time"] == rows[-1][0] and summary["steps"] == len(rows) - 1
    return rows


SELF_STEPS = [0, 1, 2, CHUNK - 2, CHUNK - 1, CHUNK, CHUNK + 1, 2 * CHUNK - 1, 2 * CHUNK,
              N_STEPS - 2, N_STEPS - 1]


def _signal_from_fmu_at(steps, tmp_path, signaller):
    """One run per step k, the FMU signalling in its do_step of step k: rows t_0..t_(k+1), no more."""
    with _Strays() as strays:
        for i, k in enumerate(steps):
            signum = (signal.SIGINT, signal.SIGTERM)[i % 2]
            case = tmp_path / f"k{k}"
            case.mkdir()
            scenario = _scenario(case, signaller, signal_time=k * STEP, signum=float(signum))
            rows = _interrupted(_invoke(scenario, case / "out"), case / "out", signum)
            assert len(rows) == k + 2, (k, len(rows))
    assert strays.count == 0


@pytest.mark.integration
def test_signals_from_inside_fmu_code_stop_the_run_before_the_next_step(tmp_path, signaller):
    """11 signals: first and last steps, both sides of each chunk flush."""
    _signal_from_fmu_at(SELF_STEPS, tmp_path, signaller)


@pytest.mark.integration
@pytest.mark.slow
def test_signals_from_inside_fmu_code_at_random_steps(tmp_path, signaller):
    """21 signals at random steps."""
    _signal_from_fmu_at(random.Random(13).sample(range(3, N_STEPS - 2), 21), tmp_path, signaller)


@pytest.mark.integration
@pytest.mark.slow
def test_signals_at_random_moments_of_runs(tmp_path, signaller):
    """32 signals from a timer at random moments of whole runs (set-up, steps, flushes, end)."""
    scenario = _scenario(tmp_path, signaller)
    t0 = time.perf_counter()
    assert _invoke(scenario, tmp_path / "calibration").exit_code == 0
    duration = time.perf_counter() - t0
    rng = random.Random(29)
    landed = 0
    with _Strays() as strays:
        for i in range(32):
            signum = (signal.SIGTERM, signal.SIGINT)[i % 2]
            out = tmp_path / f"r{i}"
            before = strays.count
            timer = threading.Timer(rng.uniform(0.0, 1.1 * duration), os.kill, (os.getpid(), signum))
            timer.start()
            result = _invoke(scenario, out)
            timer.join()
            status = json.loads((out / "summary.json").read_text())["status"]
            if strays.count > before or (status == "completed" and interrupts.received()):
                # arrived before the command listened, or after it wrote the summary
                assert result.exit_code == 0 and status == "completed", result.output
                check_whole_rows(out)
            else:
                _interrupted(result, out, signum)
                landed += 1
    assert landed >= 24, landed


@pytest.mark.integration
def test_signal_in_slow_fmu_code_takes_effect_at_once(tmp_path, signaller):
    """A real process whose FMU spends 20 ms per step and signals itself at step 20 of 10^5:
    it stops after that step (22 rows), where it used to run on to the next progress report
    (every 500 steps: 10 s more)."""
    scenario = _scenario(tmp_path, signaller, n_steps=100_000, signal_time=20 * STEP,
                         signum=float(signal.SIGTERM), busy=0.02)
    out = tmp_path / "out"
    done = run_process("run", scenario, "--out", out, "--no-plots")
    assert done.returncode == 143, done.stderr
    assert len(check_whole_rows(out)) == 22
    assert json.loads((out / "summary.json").read_text())["steps"] == 21


@pytest.mark.integration
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_signal_during_a_writer_flush(tmp_path, signaller, monkeypatch, signum):
    """The signal lands in the middle of writing the second chunk: that chunk is written whole
    and the run stops before the next step (2000 rows: the flush follows the 2000th)."""
    from aotv_cosim.output import run_files

    write = run_files.TimeSeriesWriter._write
    calls = []

    def interrupted_write(self, data):
        calls.append(len(data))
        if len(calls) == 3:  # header, first chunk, second chunk
            os.kill(os.getpid(), signum)
            sum(k * k for k in range(20000))  # the handler runs here, inside the writer
        return write(self, data)

    monkeypatch.setattr(run_files.TimeSeriesWriter, "_write", interrupted_write)
    out = tmp_path / "out"
    with _Strays() as strays:
        rows = _interrupted(_invoke(_scenario(tmp_path, signaller), out), out, signum)
    assert strays.count == 0 and len(rows) == 2 * CHUNK


def test_a_time_without_its_row_is_dropped_at_the_flush():
    """Without deferred signals a KeyboardInterrupt can land between the two appends of the
    loop; the flush then pairs times and rows instead of failing on their lengths."""
    import ctypes

    import numpy as np

    from aotv_cosim.simulation.rows import Rows

    class Coupling:
        values = (ctypes.c_double * 2)(1.0, 2.0)
        array = np.frombuffer(values)

    class Master:
        coupling = Coupling()
        received: ClassVar[list] = []

        def record(self, times, rows):
            self.received.append((list(times), rows.tolist()))

    master = Master()
    rows = Rows(master, None)
    rows.add(0.0)
    rows.times.append(0.1)  # the time of a row that was never recorded
    rows.flush()
    assert master.received == [([0.0], [[1.0, 2.0]])] and rows.times == rows.rows == []
