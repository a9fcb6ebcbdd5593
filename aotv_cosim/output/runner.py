"""Run a Scenario in memory (`simulate`) or into an output folder: time series, summary.json, plots."""

import platform
from pathlib import Path
from typing import NamedTuple

import numpy as np

from aotv_cosim import __version__
from aotv_cosim.model.variable_types import Decoder
from aotv_cosim.output import plausibility, plots
from aotv_cosim.output.outdir import claimed
from aotv_cosim.output.run_files import (
    OutputError,
    TimeSeriesWriter,
    evaluate_expectations,
    statistics,
    write_json_atomically,
)
from aotv_cosim.output.series import SeriesTable, units_of, write_parquet
from aotv_cosim.output.summary import RunSummary
from aotv_cosim.output.tracebacks import user_source
from aotv_cosim.simulation import interrupts
from aotv_cosim.simulation.master import Master, signals_to_read
from aotv_cosim.status import Status

FORMATS = ("csv", "parquet")
"""Time series files a run can write: timeseries.csv (as the run goes) and timeseries.parquet."""


class Run(NamedTuple):
    """A finished run: its summary and the recorded table (columns, times in s, rows as
    float64; `decoder` gives the columns that are not Real their types, `variable_types`)."""

    summary: RunSummary
    columns: list
    times: np.ndarray
    rows: np.ndarray
    decoder: Decoder | None = None


def recorded_columns(scenario):
    """The CSV columns: the scenario's records, then any other signal its checks and plots use."""
    extra = [s for s in signals_to_read(scenario) if s not in scenario.record
             and s not in {f"{c.source}.{c.output}" for c in scenario.system.connections}]
    wanted = scenario.record + [c.signal for c in scenario.stop_conditions]
    wanted += [e.signal for e in scenario.expectations] + extra
    return list(dict.fromkeys(wanted))


def numeric_columns(scenario) -> list:
    """The recorded columns a campaign row holds as numbers: every one but the String outputs."""
    return [c for c in recorded_columns(scenario) if scenario.system.variable(c).type != "String"]


def run_scenario(scenario, out_dir, progress=None, make_plots=True, formats=("csv",),
                 fmi_calls=None) -> RunSummary:
    """Run and write results; returns the summary (also in out_dir/summary.json)."""
    return write_run(scenario, out_dir, progress, make_plots, formats, fmi_calls).summary


def write_run(scenario, out_dir, progress=None, make_plots=True, formats=("csv",), fmi_calls=None) -> Run:
    """Run into out_dir: the time series in `formats` (FORMATS), summary.json and the plots.

    timeseries.csv is appended as the run goes (whole rows); timeseries.parquet is written at
    the end, with each field's unit in its metadata. The folder is claimed for the run
    (`outdir.claimed`: InputError if unusable or busy). A result file that cannot be written
    fails the run (`OutputError` in the summary); if summary.json itself cannot be written, that
    OutputError is raised. An interrupted run or one whose output failed draws no plots.
    fmi_calls: how the master calls the FMUs (`master.FMI_CALLS`, default its default). `formats`
    and `fmi_calls` are checked by the caller's options (`options.RunOptions`)."""
    out_dir = Path(out_dir)
    with claimed(out_dir):
        return _write_into(scenario, out_dir, progress, make_plots, formats, fmi_calls)


def _write_into(scenario, out_dir, progress, make_plots, formats, fmi_calls):
    def open_series(columns, index, decoder=None):
        return TimeSeriesWriter(out_dir, columns, index, decoder) if "csv" in formats else \
            SeriesTable(columns, index)

    run = simulate(scenario, open_series, progress, fmi_calls)
    summary, columns, times, rows, decoder = run
    if "parquet" in formats and summary.stop_reason != "output failed":
        write_parquet(out_dir / "timeseries.parquet", columns, times, rows, summary.units, decoder)
    if (make_plots and len(times) > 1 and summary.status != Status.INTERRUPTED
            and summary.stop_reason != "output failed"):
        summary.plots = plots.overview(out_dir, scenario.system, columns, times, rows, scenario.path.stem)
        summary.plots += [plots.custom(out_dir, scenario.system, spec, columns, times, rows)
                          for spec in scenario.plots]
    write_json_atomically(out_dir / "summary.json", summary.as_json())
    return run


def simulate(scenario, open_series=SeriesTable, progress=None, fmi_calls=None) -> Run:
    """Run the scenario; nothing is written but what the series object does with the rows.

    open_series(columns, index[, decoder]) makes the series object (a `SeriesTable`, kept in
    memory, or a `TimeSeriesWriter`) that is called with every chunk of rows once the buffer
    layout `index` is known; it needs `close()` and `table()`. The summary has no plots. SIGINT/SIGTERM are deferred
    (`interrupts`): a signal ends the run before its next step, or, arriving after the last step, still marks it
    interrupted. fmi_calls: as for `write_run`; the summary's "fmi_calls" says which ran."""
    with interrupts.deferred():
        return _simulate(scenario, open_series, progress, fmi_calls)


class _Series:
    """The run's recorder (`rows.Recorder`): opens the series object with `open_series` at the
    first chunk, once the master's buffer layout is known, and passes it every chunk."""

    def __init__(self, open_series, columns, master, decoder):
        self.open, self.columns, self.master, self.decoder = open_series, columns, master, decoder
        self.writer = None

    def record(self, times, rows):
        if self.writer is None:
            index = self.master.index
            self.writer = self.open(self.columns, index, self.decoder) if self.decoder else \
                self.open(self.columns, index)
        self.writer(times, rows)


def _simulate(scenario, open_series, progress, fmi_calls):
    columns = recorded_columns(scenario)
    types = {c: scenario.system.variable(c).type for c in columns}
    master = Master(scenario, progress, fmi_calls=fmi_calls)
    decoder = None
    if any(kind != "Real" for kind in types.values()):
        decoder = Decoder({c: k for c, k in types.items() if k != "Real"}, master.strings.texts)
    series = _Series(open_series, columns, master, decoder)
    outcome = master.run(series)
    attach_fmu_log(outcome, master, scenario.system)
    writer = series.writer
    try:
        if writer is None:  # failed before the first row: still leave a readable, empty series
            columns = []
            writer = open_series([], {})
        writer.close()
    except OutputError as exc:
        _output_failed(outcome, exc)
    times, rows = writer.table() if writer is not None else ([], [])
    if interrupts.received() and outcome.status == Status.COMPLETED:  # signal after the last step
        outcome.status, outcome.stop_reason = Status.INTERRUPTED, f"interrupted by {interrupts.name()}"
    final, minima, maxima = statistics(columns, times, rows, decoder)
    summary = RunSummary(
        scenario=str(scenario.path),
        system=str(scenario.system.path),
        description=scenario.description,
        status=outcome.status,
        stop_reason=outcome.stop_reason,
        warnings=_warnings(scenario, outcome),
        error=outcome.error,
        error_detail=outcome.error_detail,
        event=outcome.event,
        terminate_request=outcome.terminate_request or None,
        algorithm=scenario.algorithm,
        start=scenario.start, stop=scenario.stop, step=scenario.step,
        end_time=float(times[-1]) if len(times) else None,
        steps=outcome.steps,
        step_control=outcome.step_control,
        wall_time_s=outcome.wall_time,
        init_time_s=outcome.init_time,
        us_per_step=(outcome.wall_time - outcome.init_time) / outcome.steps * 1e6 if outcome.steps else None,
        final=final, min=minima, max=maxima,
        units=units_of(scenario.system, columns),
        types=decoder.types if decoder else None,
        expectations=evaluate_expectations(scenario.expectations, columns, times, rows, outcome.event,
                                           decoder) if outcome.status.ended_cleanly else [],
        fmi_calls=master.fmi_calls,
        fmus=outcome.fmus,
        versions={"aotv_cosim": __version__, "python": platform.python_version()},
    )
    if scenario.outcome is not None:  # classified as a campaign row would be
        from aotv_cosim.mission.outcome_rows import run_outcome

        summary.outcome = run_outcome(summary.as_json(), scenario.outcome)
    # a failed or interrupted run says nothing of its physics: only the values given are judged then
    summary.warnings += plausibility.run_warnings(scenario, summary) \
        if summary.status not in (Status.FAILED, Status.INTERRUPTED) else plausibility.unit_slips(scenario.system)
    return Run(summary, columns, times, rows, decoder)


def _output_failed(outcome, exc):
    """Record a result file that could not be written as the run's failure (unless it failed already)."""
    if outcome.status != Status.FAILED:
        outcome.status, outcome.error, outcome.stop_reason = Status.FAILED, str(exc), "output failed"
        outcome.error_detail = {"component": None, "variable": None, "time": None, "message": exc.cause}


def attach_fmu_log(outcome, master, system):
    """Add the failing component's log messages ('status: text', oldest first) to error_detail, the
    last Python traceback it logged, lines kept, as error_detail["traceback"], and, when the
    component is a user's .py source, its full path as error_detail["source"] (`tracebacks`)."""
    detail = outcome.error_detail
    instance = master.instances.get(detail.get("component")) if detail else None
    if instance is not None:
        detail["fmu_log"] = [f"{status}: {' '.join(text.split())}" for status, text in instance.messages]
        tracebacks = [text for _, text in instance.messages if "Traceback (most recent call last)" in text]
        if tracebacks:  # an exception in the FMU's Python code, logged by AotvSlave: keep its lines
            detail["traceback"] = tracebacks[-1].strip()
            source = user_source(system, detail.get("component"))
            if source is not None:
                detail["source"] = str(source)


def _warnings(scenario, outcome):
    """What a completed run did not do that the scenario asked for: a stop condition never met,
    expectations not checked because the time span was overridden, a tolerance whose global
    error estimate is still above it after the last attempt (`simulation.step_doubling`); a run that
    records no signal beyond time; and the wiring's warnings
    (a unit on one side only of a connection)."""
    warnings = list(scenario.system.warnings) + _unrecorded(recorded_columns(scenario))
    warnings += [f"{len(scenario.skipped)} expectation(s) not checked: start/stop overridden "
                 f"(run {scenario.start:g}..{scenario.stop:g} s)"] if scenario.skipped else []
    control = outcome.step_control or {}
    if control.get("tolerance_met") is False:
        asked = scenario.step_control.tolerance
        warnings += [f"global error of {sig} " + (f"estimated {err:.3g}, above its tolerance {asked[sig]:g}"
                                                   if err is not None else "not estimated (its coarse runs failed)")
                     + f", after {control['attempts']} attempts"
                     for sig, err in control["global_error"].items() if err is None or err > asked[sig]]
    if outcome.status != Status.COMPLETED or not scenario.stop_conditions or outcome.event is not None:
        return warnings
    conditions = ", ".join(f"{c.signal} changing" if c.threshold is None else
                           f"{c.signal} crossing {c.threshold:g} ({c.direction})" for c in scenario.stop_conditions)
    return [*warnings, f"no stop condition was met before the stop time {scenario.stop:g} s: {conditions}"]



def _unrecorded(columns) -> list:
    """A warning when the run records no signal beyond time (the default record holds every
    output of every type, so it leaves none out)."""
    if columns:
        return []
    return ["no signal is recorded beyond time: the system has no output (add a component with outputs)"]
