"""A campaign from start to report: draws, batches, a backend, rows on disk, statistics."""

import contextlib
import json
import time
from pathlib import Path
from typing import IO, cast

from aotv_cosim.campaigns import backends, report, statistics
from aotv_cosim.campaigns.draws import draw
from aotv_cosim.campaigns.scenario_ref import ScenarioRef
from aotv_cosim.campaigns.store import RowStore
from aotv_cosim.campaigns.units import column_units
from aotv_cosim.campaigns.worker import columns
from aotv_cosim.errors import InputError
from aotv_cosim.model.scenario import Scenario
from aotv_cosim.options import CampaignOptions
from aotv_cosim.options.checks import check_fits
from aotv_cosim.output import plausibility
from aotv_cosim.output.outdir import claimed, remove_written
from aotv_cosim.output.run_files import write_json_atomically
from aotv_cosim.output.tracebacks import first_user_line
from aotv_cosim.simulation import interrupts
from aotv_cosim.simulation.master import FMI_CALLS_DEFAULT, Interrupted
from aotv_cosim.status import Status

FAILURES = "failures.jsonl"
"""Every failed run of a campaign, one JSON object a line: run, status, error, the dispersed values
and, when an FMU's Python code raised, its traceback and the user's source file."""
CAMPAIGN_FILES = ("rows.csv", "rows.csv.part", "rows.parquet", "rows.parquet.part", "campaign.json",
                  "summary.json", "summary.json.part", FAILURES, "report.md", "histograms.png", "versus.png",
                  "scatter.png", "series.parquet", "series.parquet.part", "trajectories.png")
"""What a campaign writes in its folder."""


def run_campaign(options: CampaignOptions) -> dict:
    """Run `options.runs` dispersed runs of `options.scenario` into `options.out`; returns the
    campaign summary (summary.json).

    The local pool (`options.workers` processes) or the Dask scheduler (`options.scheduler`) gives
    the same rows. The summary's `units` give every column's. With `keep_series` every run's
    recorded signals, decimated to about 200 rows, go to series.parquet (and the Monte Carlo
    trajectory overlay is drawn, `figures.trajectories`). SIGINT/SIGTERM (deferred, see
    `interrupts`) stop the campaign: the finished runs are kept (rows.csv, rows.parquet),
    summary.json says status 'interrupted', and `resume` runs the rest. A run that passes the step
    limit or the memory limit, or crashes its worker, is a 'failed' row with the cause (`pool`).
    """
    scenario = cast(Path, options.scenario)  # a loaded Scenario is given as its path (`CampaignOptions`)
    ref = ScenarioRef.of(Path(scenario).resolve(), options.overrides, options.start, options.stop)
    return fly(ref, ref.load(), options, options.out)


def fly(ref: ScenarioRef, scenario: Scenario, options, out) -> dict:
    """`run_campaign` of the scenario `ref`, already loaded as `scenario`, into the folder `out`,
    with the command's options (`runs`, `seed`, `resume`, `plots`, `keep_series` and how the runs
    are made, `options.RunsOptions`; a benchmark gives its own for each of its laws)."""
    if not scenario.dispersions:
        raise InputError("the scenario declares no dispersions", file=ref.path, entry="dispersions",
                         fix='add "dispersions": {"component.parameter": {"distribution": ...}}')
    names = columns(scenario)
    check_fits(options.runs, len(names), ref.path)
    created = not Path(out).exists()
    try:
        with interrupts.deferred(), claimed(out, CAMPAIGN_FILES, adopt=options.resume):
            return _campaign(ref, scenario, Path(out), options)
    except InputError:
        if created:  # refused before any run (an unusable scheduler, a report column): leave no folder
            remove_written(out)
        raise


class Failures:
    """failures.jsonl of a campaign folder (`FAILURES`), written at the first failed run and appended
    as failed runs come in (flushed: an interruption keeps them); a new campaign removes the one
    of an earlier campaign in the folder, a resumed one continues it."""

    def __init__(self, path: Path, resume: bool):
        self.path = path
        self.file: IO[str] | None = None
        if not resume:
            path.unlink(missing_ok=True)

    def add(self, row, failure) -> None:
        """Record `row` if its run did not complete, with `failure` ({"traceback", "source"} or None)."""
        if row["status"] == Status.COMPLETED:
            return
        if self.file is None:
            self.file = open(self.path, "a", encoding="utf-8")  # noqa: SIM115 (kept open as runs fail; `close`)
        entry = {"run": row["run"], "status": str(row["status"]), "error": row["error"], **(failure or {}),
                 "dispersed": {k.split(".", 1)[1]: v for k, v in row.items() if k.startswith("dispersed.")}}
        self.file.write(json.dumps(entry, default=str) + "\n")
        self.file.flush()

    def close(self) -> None:
        if self.file is not None:
            self.file.close()

    def summary(self) -> "dict | None":
        """{"count", "file", "first": {"run", "where"}}: how many runs failed (over every session) and
        where the first (lowest run) failed: the user's file, line and exception when an FMU's
        Python code raised, else the error; None when none failed."""
        entries = {}
        if not self.path.is_file():
            return None
        with open(self.path, encoding="utf-8") as f:
            for line in f:
                with contextlib.suppress(ValueError):
                    entry = json.loads(line)
                    entries[entry["run"]] = entry
        if not entries:
            return None
        first = entries[min(entries)]
        where = first_user_line(first["traceback"], first.get("source")) if first.get("traceback") else ""
        return {"count": len(entries), "file": FAILURES,
                "first": {"run": first["run"], "where": where or " ".join(str(first["error"]).split())}}


def _campaign(ref, scenario, out, options):
    runs = options.runs
    step_limit = options.step_limit(scenario)
    names = columns(scenario)
    report.chosen(scenario, names)  # refuse an unknown report column before any run
    manifest = {"scenario": ref.path, "runs": runs, "seed": options.seed, "sets": ref.overrides,
                "dispersions": [d.__dict__ for d in scenario.dispersions],
                **({"start": ref.start, "stop": ref.stop} if ref.times_overridden else {})}
    units = column_units(scenario, names)
    store = RowStore(out, names, manifest, options.resume, units)
    failures = Failures(out / FAILURES, options.resume)
    done = store.done()
    todo = runs - len(done)
    work = ((k, draw(scenario.dispersions, options.seed, k)) for k in range(runs) if k not in done)
    local = options.scheduler is None
    backend = backends.opened(options, step_limit, names)
    series = {}
    bar = None
    if options.progress:
        from tqdm import tqdm

        bar = tqdm(total=runs, initial=runs - todo, unit="run", desc="runs", smoothing=0.1)
    t0 = time.perf_counter()
    status = Status.COMPLETED
    interrupted = True  # until the runs are through: anything else stops the backend's pending work
    try:
        for rows in backends.stream(backend, ref, work, todo):
            for row in rows:
                if "series" in row:
                    series[row["run"]] = row.pop("series")
                failures.add(row, row.pop("failure", None))
                store.add(row)
            if bar is not None:
                bar.update(len(rows))
            if interrupts.received():
                raise Interrupted(interrupts.name())
        interrupted = False
    except Interrupted:
        status = Status.INTERRUPTED
    finally:
        backend.close(interrupted)
        failures.close()
        if bar is not None:
            bar.close()
    wall = time.perf_counter() - t0
    rows = store.close()
    statuses: dict = {}
    for r in rows:  # keyed by the text, as campaign.json and the console show it
        statuses[str(r["status"])] = statuses.get(str(r["status"]), 0) + 1
    summary = {
        "status": status.value,
        "stop_reason": f"interrupted by {interrupts.name()}" if status == Status.INTERRUPTED else None,
        "scenario": ref.path, "runs": runs, "seed": options.seed,
        "backend": "local" if local else "dask", "workers": options.workers,
        "fmi_calls": options.fmi_calls or FMI_CALLS_DEFAULT,
        "runs_this_session": len(rows) - len(done), "wall_time_s": wall,
        "runs_per_s": (len(rows) - len(done)) / wall if wall > 0 else None,
        "statuses": statuses,
        "warnings": plausibility.unit_slips(scenario.system),
        "limits": {"step_timeout_s": step_limit,
                   "max_rss_mib": options.max_rss},
        "runs_left": runs - len(rows),
        "failed": [{"run": r["run"], "status": r["status"], "error": r["error"]}
                   for r in rows if r["status"] != Status.COMPLETED][:50],
        "failures": failures.summary(),
        "statistics": statistics.statistics(rows, names),
        "units": units,
    }
    plots = options.plots and status == Status.COMPLETED
    summary.update(report.write(out, rows, scenario, units, names, plots))
    if options.keep_series:
        from aotv_cosim.campaigns.series import write_series

        summary["plots"] += write_series(out, series, scenario, ref, options, plots)
    write_json_atomically(out / "summary.json", summary)
    return summary
