"""One worker's side of a campaign: the scenario loaded once, FMUs reused, runs turned into rows.

A worker process keeps one `Runner` per `ScenarioRef` (scenario file, --set values, times), per
options object (the command's whole `options.RunsOptions`, as the parent made it) and per thread,
so the FMUs are instantiated once per worker and only reset (fmi2Reset) between runs. A row holds
no timing, so the same run gives the same row on any worker and backend.
"""

import math
import threading
from typing import Any

import numpy as np

from aotv_cosim.campaigns.scenario_ref import ScenarioRef
from aotv_cosim.mission import outcome_rows
from aotv_cosim.options import RunsOptions
from aotv_cosim.output.runner import attach_fmu_log, numeric_columns
from aotv_cosim.simulation.master import Master
from aotv_cosim.status import Status

_LOCAL = threading.local()


def columns(scenario) -> list:
    """Row columns: run, status, error, dispersed values, end, final/min/max and exit values."""
    signals = numeric_columns(scenario)
    names = ["run", "status", "error"] + [f"dispersed.{d.signal}" for d in scenario.dispersions]
    names += ["end_time", "steps"] + [f"final.{s}" for s in signals]
    names += [f"min.{s}" for s in signals] + [f"max.{s}" for s in signals]
    if scenario.stop_conditions:
        names += ["exit.time"] + [f"exit.{s}" for s in signals]
    if scenario.outcome is not None:
        names += list(outcome_rows.UNITS)
    return names


SERIES_POINTS = 200
"""About how many rows of its recorded signals a run keeps with keep_series (evenly in time)."""


class _Extrema:
    """A run's recorder (`simulation.rows.Recorder`) keeping only the last row and running min/max of
    `signals`, and, when `spacing` (s) is given, the rows at least that far apart in time (`series`)."""

    def __init__(self, master, signals, spacing=None):
        self.master, self.signals = master, signals
        self.select = None
        self.last: np.ndarray | None = None
        self.low: np.ndarray | None = None
        self.high: np.ndarray | None = None
        self.time = math.nan
        """Time of the last row recorded, s."""
        self.spacing, self.series, self.kept_at = spacing, [], -math.inf

    def record(self, times, rows):
        if self.select is None:  # the master's buffer layout is known once it runs
            self.select = [self.master.index[s] for s in self.signals]
        rows = rows[:, self.select]
        low, high = np.nanmin(rows, axis=0), np.nanmax(rows, axis=0)
        self.low = low if self.low is None else np.fmin(self.low, low)
        self.high = high if self.high is None else np.fmax(self.high, high)
        self.last, self.time = rows[-1], float(times[-1])
        if self.spacing is not None:
            for t, row in zip(times, rows):
                if t >= self.kept_at + self.spacing:
                    self.series.append((float(t), *map(float, row)))
                    self.kept_at = t

    def kept(self) -> dict:
        """{"time": [...], signal: [...]}: the kept rows and the last one."""
        rows = list(self.series)
        if self.last is not None and (not rows or rows[-1][0] < self.time):
            rows.append((self.time, *map(float, self.last)))
        return dict(zip(["time", *self.signals], map(list, zip(*rows)))) if rows else {}


class Runner:
    """Runs draws of one scenario on FMUs kept between runs."""

    def __init__(self, ref: ScenarioRef, options: RunsOptions | None = None):
        """options: the command's options (None: the defaults of `RunsOptions`), of which a runner
        uses `keep_series` (keep each run's recorded signals, decimated to `SERIES_POINTS`),
        `step_limit` (the wall-clock limit per step, `simulation.watchdog`) and `fmi_calls` (how
        the master calls the FMUs, `simulation.master`)."""
        options = options if options is not None else RunsOptions()
        self.scenario = ref.load()
        self.scenario.step_timeout = options.step_limit(self.scenario)
        self.spacing = (self.scenario.stop - self.scenario.start) / SERIES_POINTS if options.keep_series else None
        self.signals = numeric_columns(self.scenario)
        self.columns = columns(self.scenario)
        self.pool: dict = {}
        self.fmi_calls = options.fmi_calls

    def run(self, run: int, values: dict) -> dict:
        """The row of one run with the dispersed `values` ({'comp.var': value}), classified when
        the scenario asks for outcomes; with keep_series, its decimated recorded signals under
        "series" (not a column: the campaign writes them to series.parquet); when an FMU's Python
        code raised, {"traceback", "source"} under "failure" (`output.tracebacks`; not a column:
        the campaign writes it to failures.jsonl)."""
        row = self._run(run, values)
        if self.scenario.outcome is not None:
            row.update(outcome_rows.outcome_columns(row, self.scenario.outcome))
        return row

    def _run(self, run: int, values: dict) -> dict:
        row: dict[str, Any] = dict.fromkeys(self.columns, math.nan)
        row.update(run=run, status=Status.ERROR, error="")
        row.update({f"dispersed.{k}": v for k, v in values.items()})
        try:
            master = Master(self.scenario, overrides=values, pool=self.pool, fmi_calls=self.fmi_calls)
            extrema = _Extrema(master, self.signals, self.spacing)
            outcome = master.run(extrema)
        except Exception as exc:  # a bad draw (e.g. a value the FMU rejects): record it, go on
            row["error"] = f"{type(exc).__name__}: {exc}"
            return row
        row.update(status=outcome.status, error=outcome.error or "", steps=outcome.steps,
                   end_time=extrema.time)
        if outcome.error_detail:
            attach_fmu_log(outcome, master, self.scenario.system)
            if outcome.error_detail.get("traceback"):
                row["failure"] = {key: outcome.error_detail.get(key) for key in ("traceback", "source")}
        if self.spacing is not None:
            row["series"] = extrema.kept()
        last, low, high = extrema.last, extrema.low, extrema.high
        if last is not None and low is not None and high is not None:  # all three or none (`record`)
            for k, s in enumerate(self.signals):
                row[f"final.{s}"] = float(last[k])
                row[f"min.{s}"] = float(low[k])
                row[f"max.{s}"] = float(high[k])
        if outcome.event:
            row["exit.time"] = float(outcome.event["time"])
            row.update({f"exit.{s}": float(outcome.event["values"][s]) for s in self.signals})
        return row


def runner(ref: ScenarioRef, options: RunsOptions) -> Runner:
    """This thread's Runner for the scenario and options (made on first use)."""
    cache = getattr(_LOCAL, "runners", None)
    if cache is None:
        cache = _LOCAL.runners = {}
    if (ref, options) not in cache:
        cache[ref, options] = Runner(ref, options)
    return cache[ref, options]


def run_batch(ref: ScenarioRef, options: RunsOptions, batch) -> list:
    """Rows of a batch [(run, values), ...] (the task sent to a Dask worker)."""
    r = runner(ref, options)
    return [r.run(run, values) for run, values in batch]


def run_one(ref: ScenarioRef, options: RunsOptions, run, values) -> dict:
    """The row of one run (the task sent to a local worker)."""
    return runner(ref, options).run(run, values)


def release() -> None:
    """Close the FMU instances this thread's Runners keep (a local worker does so before it exits,
    so no FMU library is left to the interpreter's exit-time destructors)."""
    for kept in getattr(_LOCAL, "runners", {}).values():
        for instance in kept.pool.values():
            instance.close()
        kept.pool.clear()
