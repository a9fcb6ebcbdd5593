"""A campaign from start to report: draws, batches, a backend, rows on disk, statistics."""

import time
from pathlib import Path

from aotv_cosim.engine import interrupts, plausibility, watchdog
from aotv_cosim.errors import InputError
from aotv_cosim.engine.master import Interrupted
from aotv_cosim.campaigns import backends, campaign_report, report
from aotv_cosim.campaigns.draws import draw
from aotv_cosim.campaigns.pool import DEFAULT_MAX_RSS
from aotv_cosim.campaigns.store import RowStore
from aotv_cosim.campaigns.units import column_units
from aotv_cosim.campaigns.worker import columns
from aotv_cosim.engine.outdir import claimed
from aotv_cosim.engine.results import write_json_atomically
from aotv_cosim.engine.scenario import load_scenario


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
                 step_timeout=None, max_rss=DEFAULT_MAX_RSS) -> dict:
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
    """
    scenario_path = Path(scenario_path).resolve()
    scenario = load_scenario(scenario_path, sets, start=start, stop=stop)
    times = (start, stop) if start is not None or stop is not None else None
    if not scenario.dispersions:
        raise InputError("the scenario declares no dispersions", file=scenario_path, entry="dispersions",
                         fix='add "dispersions": {"component.parameter": {"distribution": ...}}')
    limits = (step_timeout or scenario.step_timeout or watchdog.CAMPAIGN_STEP_TIMEOUT, max_rss)
    with interrupts.deferred(), claimed(out_dir, CAMPAIGN_FILES):
        return _campaign(scenario, scenario_path, runs, Path(out_dir), workers, seed, scheduler, resume,
                         sets, progress, make_plots, times, limits, keep_series)


def _campaign(scenario, scenario_path, runs, out, workers, seed, scheduler, resume, sets, progress,
              make_plots, times, limits, keep_series):
    names = columns(scenario)
    campaign_report.chosen(scenario, names)  # refuse an unknown report column before any run
    manifest = {"scenario": str(scenario_path), "runs": runs, "seed": seed, "sets": sets or {},
                "dispersions": [d.__dict__ for d in scenario.dispersions],
                **({"start": times[0], "stop": times[1]} if times else {})}
    units = column_units(scenario, names)
    store = RowStore(out, names, manifest, resume, units)
    todo = [k for k in range(runs) if k not in store.done()]
    work = [(k, draw(scenario.dispersions, seed, k)) for k in todo]
    n_workers = workers if scheduler is None else max(1, workers)
    chunks = batches_of(work, n_workers)
    source = (backends.local(str(scenario_path), sets, chunks, workers, names, times, *limits,
                             keep_series=keep_series) if scheduler is None
              else backends.dask(str(scenario_path), sets, chunks, scheduler, names, times, keep_series=keep_series))
    series = {}
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=runs, initial=runs - len(todo), unit="run", desc="runs", smoothing=0.1)
    t0 = time.perf_counter()
    status = "completed"
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
        status = "interrupted"
    finally:
        source.close()  # on an interruption, stop the backend's pending work
        if bar is not None:
            bar.close()
    wall = time.perf_counter() - t0
    rows = store.close()
    statuses = {}
    for r in rows:
        statuses[r["status"]] = statuses.get(r["status"], 0) + 1
    summary = {
        "status": status, "stop_reason": f"interrupted by {interrupts.name()}" if status == "interrupted" else None,
        "scenario": str(scenario_path), "runs": runs, "seed": seed,
        "backend": "local" if scheduler is None else "dask", "workers": workers,
        "runs_this_session": len(rows) - (runs - len(todo)), "wall_time_s": wall,
        "runs_per_s": (len(rows) - (runs - len(todo))) / wall if wall > 0 else None,
        "statuses": statuses,
        "warnings": plausibility.unit_slips(scenario.system),
        "limits": {"step_timeout_s": limits[0], "max_rss_mib": limits[1] / 2**20 if limits[1] else None},
        "failed": [{"run": r["run"], "status": r["status"], "error": r["error"]}
                   for r in rows if r["status"] != "completed"][:50],
        "statistics": report.statistics(rows, names),
        "units": units,
    }
    summary.update(campaign_report.write(out, rows, scenario, units, names,
                                         make_plots and status == "completed"))
    if keep_series:
        from aotv_cosim.campaigns.series import write_series

        summary["plots"] += write_series(out, series, scenario, str(scenario_path), sets, times,
                                         make_plots and status == "completed")
    write_json_atomically(out / "summary.json", summary)
    return summary
