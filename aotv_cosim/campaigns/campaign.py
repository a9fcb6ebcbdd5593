"""A campaign from start to report: draws, batches, a backend, rows on disk, statistics."""

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

from aotv_cosim.simulation import interrupts, watchdog

from aotv_cosim.output import plausibility
from aotv_cosim.errors import InputError
from aotv_cosim.simulation.master import FMI_CALLS_DEFAULT, Interrupted
from aotv_cosim.campaigns import backends, report, statistics
from aotv_cosim.campaigns.draws import draw
from aotv_cosim.campaigns.pool import DEFAULT_MAX_RSS
from aotv_cosim.campaigns.scenario_ref import ScenarioRef
from aotv_cosim.campaigns.store import RowStore
from aotv_cosim.campaigns.units import column_units
from aotv_cosim.campaigns.worker import columns
from aotv_cosim.output.outdir import claimed
from aotv_cosim.output.run_files import write_json_atomically
from aotv_cosim.model.scenario import Scenario
from aotv_cosim.status import Status


CAMPAIGN_FILES = ("rows.csv", "rows.csv.part", "rows.parquet", "rows.parquet.part", "campaign.json",
                  "summary.json", "summary.json.part")
"""What a campaign writes (besides its plots) and so must not find there as folders."""


def batches_of(items, workers):
    """Batches of consecutive runs (Dask tasks; the local pool takes them a run at a time, so that
    a lost worker costs one run), shrinking to the end (guided scheduling): each holds an eighth
    of a worker's share of the runs still to batch, at most 25 and at least 1. A batch amortizes
    the task overhead, and the last ones are single runs, so no worker idles long while another
    finishes a batch: with even batches of 12, 200 predictive-law runs on 2 workers kept the
    workers busy 89 % of the wall time (the last batch is 3.7 s of one worker)."""
    batches, k = [], 0
    while k < len(items):
        size = max(1, min(25, (len(items) - k) // (8 * max(1, workers))))
        batches.append(items[k:k + size])
        k += size
    return batches


def run_campaign(scenario_path, runs, out_dir, workers=1, seed=0, scheduler=None, resume=False,
                 sets=None, progress=True, make_plots=True, start=None, stop=None, keep_series=False,
                 step_timeout=None, max_rss=DEFAULT_MAX_RSS, fmi_calls=None) -> dict:
    """Run `runs` dispersed runs of the scenario; returns the campaign summary (summary.json).

    scheduler: None for a local pool of `workers` processes, else a Dask scheduler address
    (or a distributed.Client). The rows do not depend on either choice. start, stop (s)
    override the scenario's times (--start, --stop). The summary's `units` give every column's.
    keep_series: also write every run's recorded signals, decimated to about 200 rows, to
    series.parquet (and draw the Monte Carlo trajectory overlay, `figures.trajectories`).
    SIGINT/SIGTERM (deferred, see `interrupts`) stop the campaign: the finished runs are kept
    (rows.csv, rows.parquet), summary.json says status 'interrupted', and --resume runs the rest.
    step_timeout: wall-clock limit of one step, s (default the scenario's step_timeout, else
    `watchdog.CAMPAIGN_STEP_TIMEOUT`); max_rss: a local worker's memory limit, bytes (None: none).
    A run that passes either, or crashes its worker, is a 'failed' row with the cause (`pool`).
    fmi_calls: "c" or "direct" (`simulation.master`; None: its default, "direct"); the rows do not
    depend on it.
    """
    ref = ScenarioRef.of(Path(scenario_path).resolve(), sets, start, stop)
    options = CampaignOptions(workers, seed, scheduler, resume, progress, make_plots, keep_series, step_timeout,
                              max_rss, fmi_calls)
    return fly(ref, ref.load(), runs, out_dir, options)


@dataclass(frozen=True)
class CampaignOptions:
    """How a campaign's runs are made and reported (the options of `run_campaign`)."""

    workers: int = 1
    """Local worker processes (with a scheduler: at least one batch per worker)."""
    seed: int = 0
    scheduler: object = None
    """None for local workers, else a Dask scheduler address or distributed.Client."""
    resume: bool = False
    progress: bool = True
    make_plots: bool = True
    keep_series: bool = False
    step_timeout: Optional[float] = None
    """Wall-clock limit of one step, s (None: the scenario's, else `watchdog.CAMPAIGN_STEP_TIMEOUT`)."""
    max_rss: Optional[int] = DEFAULT_MAX_RSS
    """A local worker's memory limit, bytes (None: none)."""
    fmi_calls: Optional[str] = None
    """How the master calls the FMUs, "c" or "direct" (None: `master.FMI_CALLS_DEFAULT`)."""


def fly(ref: ScenarioRef, scenario: Scenario, runs: int, out_dir, options: CampaignOptions) -> dict:
    """`run_campaign` of the scenario `ref`, already loaded as `scenario`."""
    if not scenario.dispersions:
        raise InputError("the scenario declares no dispersions", file=ref.path, entry="dispersions",
                         fix='add "dispersions": {"component.parameter": {"distribution": ...}}')
    with interrupts.deferred(), claimed(out_dir, CAMPAIGN_FILES):
        return _campaign(ref, scenario, runs, Path(out_dir), options)


def _campaign(ref, scenario, runs, out, options):
    step_limit = options.step_timeout or scenario.step_timeout or watchdog.CAMPAIGN_STEP_TIMEOUT
    names = columns(scenario)
    report.chosen(scenario, names)  # refuse an unknown report column before any run
    manifest = {"scenario": ref.path, "runs": runs, "seed": options.seed, "sets": ref.overrides,
                "dispersions": [d.__dict__ for d in scenario.dispersions],
                **({"start": ref.start, "stop": ref.stop} if ref.times_overridden else {})}
    units = column_units(scenario, names)
    store = RowStore(out, names, manifest, options.resume, units)
    todo = [k for k in range(runs) if k not in store.done()]
    work = [(k, draw(scenario.dispersions, options.seed, k)) for k in todo]
    local = options.scheduler is None
    chunks = batches_of(work, options.workers if local else max(1, options.workers))
    source = (backends.local(ref, chunks, options.workers, names, step_limit, options.max_rss,
                             keep_series=options.keep_series, fmi_calls=options.fmi_calls) if local
              else backends.dask(ref, chunks, options.scheduler, names, keep_series=options.keep_series,
                                 fmi_calls=options.fmi_calls))
    series = {}
    bar = None
    if options.progress:
        from tqdm import tqdm

        bar = tqdm(total=runs, initial=runs - len(todo), unit="run", desc="runs", smoothing=0.1)
    t0 = time.perf_counter()
    status = Status.COMPLETED
    try:
        for rows in source:
            for row in rows:
                if "series" in row:
                    series[row["run"]] = row.pop("series")
                store.add(row)
            if bar is not None:
                bar.update(len(rows))
            if interrupts.received():
                raise Interrupted(interrupts.name())
    except Interrupted:
        status = Status.INTERRUPTED
    finally:
        source.close()  # on an interruption, stop the backend's pending work
        if bar is not None:
            bar.close()
    wall = time.perf_counter() - t0
    rows = store.close()
    statuses = {}
    for r in rows:  # keyed by the text, as campaign.json and the console show it
        statuses[str(r["status"])] = statuses.get(str(r["status"]), 0) + 1
    summary = {
        "status": status.value,
        "stop_reason": f"interrupted by {interrupts.name()}" if status == Status.INTERRUPTED else None,
        "scenario": ref.path, "runs": runs, "seed": options.seed,
        "backend": "local" if local else "dask", "workers": options.workers,
        "fmi_calls": options.fmi_calls or FMI_CALLS_DEFAULT,
        "runs_this_session": len(rows) - (runs - len(todo)), "wall_time_s": wall,
        "runs_per_s": (len(rows) - (runs - len(todo))) / wall if wall > 0 else None,
        "statuses": statuses,
        "warnings": plausibility.unit_slips(scenario.system),
        "limits": {"step_timeout_s": step_limit,
                   "max_rss_mib": options.max_rss / 2**20 if options.max_rss else None},
        "failed": [{"run": r["run"], "status": r["status"], "error": r["error"]}
                   for r in rows if r["status"] != Status.COMPLETED][:50],
        "statistics": statistics.statistics(rows, names),
        "units": units,
    }
    plots = options.make_plots and status == Status.COMPLETED
    summary.update(report.write(out, rows, scenario, units, names, plots))
    if options.keep_series:
        from aotv_cosim.campaigns.series import write_series

        summary["plots"] += write_series(out, series, scenario, ref, plots)
    write_json_atomically(out / "summary.json", summary)
    return summary
