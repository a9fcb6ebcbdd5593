"""Guidance benchmark (issue 16 item 5): every law of a scenario set through the same dispersions.

A set is a folder of scenario files (e.g. scenarios/benchmark_seed000/), one law each, that share
one dispersion set and classify their runs (`montecarlo.outcome`). Each law is a campaign of N
runs with the same campaign seed, so run k of every law flies the same draws (`dispersion_sets`).
Written in the output folder: one campaign folder per law (rows, summary.json, report.md, plots),
`rows.csv` / `rows.parquet` with every law's rows and a `law` column, `scorecard.csv` and
`scorecard.json` (one row per law, units beside), `benchmark.png` (overlaid distributions) and
`report.md`.

CPU per run is the CPU time (user + system) of the local worker processes, read from
`resource.getrusage(RUSAGE_CHILDREN)` once their pool is shut down, plus this process's, divided
by the runs; on a Dask cluster the workers' CPU is not seen from here and it is None.
"""

import resource
from pathlib import Path

import numpy as np

from aotv_cosim.campaigns import limits as limits_of_runs
from aotv_cosim.campaigns.campaign import run_campaign
from aotv_cosim.campaigns.outcome import OUTCOMES
from aotv_cosim.campaigns.store import write_parquet
from aotv_cosim.campaigns.worker import columns
from aotv_cosim.engine.errors import InputError
from aotv_cosim.engine.results import write_json_atomically
from aotv_cosim.engine.scenario import load_scenario

PERCENT = (0.135, 50.0, 99.865)

METRICS = (("outcome.apogee_error", "apogee error", "m", PERCENT),
           ("outcome.dv_total", "correction dv", "m/s", PERCENT),
           ("outcome.peak_heat_rate", "peak heat rate", "W/m2", (50.0, 99.865)),
           ("outcome.heat_load", "heat load", "J/m2", (50.0, 99.865)),
           ("outcome.peak_load_factor", "peak load factor", "1", (50.0, 99.865)),
           ("outcome.int_abs_u", "int |u| dt", "m/s", (50.0, 99.865)),
           ("outcome.int_u2", "int u^2 dt", "m2/s3", (50.0,)))
"""(row column, label, unit, percentiles) of the scorecard; percentiles over the completed runs
whose value is finite (an unbound exit orbit has no finite apogee error)."""


def scenarios_of(set_dir) -> list:
    """The set's scenario files, sorted, checked before any run: each classifies its runs and all
    give the same campaign columns. InputError for an empty or unusable set."""
    folder = Path(set_dir)
    if not folder.is_dir():
        raise InputError("not a folder", file=folder,
                         fix="give a folder of scenario files, one law each (e.g. scenarios/benchmark_seed000)")
    paths = sorted(folder.glob("*.json"))
    if not paths:
        raise InputError("the folder holds no scenario file", file=folder, fix="put one *.json scenario per law in it")
    first = None
    for path in paths:
        scenario = load_scenario(path)
        if scenario.outcome is None:
            raise InputError("the scenario does not classify its runs", file=path, entry="montecarlo",
                             fix='add "montecarlo": {"outcome": {}} (and record the vehicle h, v, gamma)')
        first = first or columns(scenario)
        if columns(scenario) != first:
            raise InputError(f"its campaign columns differ from those of {paths[0].name}", file=path,
                             entry="record", fix="record the same signals and disperse the same values in every law")
    return paths


def _cpu_seconds():
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def score_columns() -> list:
    """(column, unit) of the scorecard, in order."""
    cols = [("law", ""), ("runs", "1"), ("capture_rate", "%")] + [(o, "1") for o in OUTCOMES]
    for column, _, unit, percents in METRICS:
        cols += [(f"{column.split('.', 1)[1]}_p{p:g}", unit) for p in percents]
    return cols + [("cpu_per_run", "s")]


def score(law, rows, cpu_per_run) -> dict:
    """The scorecard row of one law's campaign rows (None: a figure the runs do not give)."""
    counts = {o: sum(r["outcome"] == o for r in rows) for o in OUTCOMES}
    card = {"law": law, "runs": len(rows), "capture_rate": 100.0 * counts["captured"] / len(rows), **counts}
    done = [r for r in rows if r["status"] == "completed"]
    for column, _, _, percents in METRICS:
        x = np.array([float(r[column]) for r in done], dtype=float)
        x = x[np.isfinite(x)]
        for p in percents:
            card[f"{column.split('.', 1)[1]}_p{p:g}"] = float(np.percentile(x, p)) if len(x) else None
    card["cpu_per_run"] = cpu_per_run
    return card


def run_benchmark(set_dir, runs, out_dir, workers=1, seed=0, scheduler=None, progress=True) -> dict:
    """Fly every scenario of the set for `runs` runs; returns (and writes as scorecard.json) the
    set, runs, seed, "scorecard" (one dict per law), its "units", "wall_time_s" of all the
    campaigns, "laws" ({law: {scenario, wall_time_s}}) and "plots"."""
    import pyarrow.parquet as pq

    from aotv_cosim.campaigns import benchmark_report

    paths = scenarios_of(set_dir)
    limits = limits_of_runs.of_set(paths)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cards, laws, every_row, names = [], {}, [], None
    for path in paths:
        law = path.stem
        cpu0 = _cpu_seconds()
        summary = run_campaign(path, runs, out / law, workers=workers, seed=seed, scheduler=scheduler,
                               progress=progress)
        cpu = (_cpu_seconds() - cpu0) / runs if scheduler is None else None
        rows = pq.read_table(out / law / "rows.parquet").to_pylist()
        cards.append({**score(law, rows, cpu), **limits_of_runs.score(rows, limits)})
        laws[law] = summary
        names = names or ["law"] + list(rows[0])
        units = {"law": "", **summary["units"]}
        every_row += [{"law": law, **r} for r in rows]
    units_of_scores = dict(score_columns() + limits_of_runs.columns(limits))
    result = {"set": str(Path(set_dir).resolve()), "runs": runs, "seed": seed, "scorecard": cards,
              "units": units_of_scores, "wall_time_s": sum(s["wall_time_s"] for s in laws.values()),
              "laws": {k: {"scenario": s["scenario"], "wall_time_s": s["wall_time_s"]} for k, s in laws.items()}}
    _write_scorecard(out, cards, units_of_scores)
    write_parquet(every_row, names, out / "rows.parquet", units)
    _write_rows_csv(out / "rows.csv", every_row, names)
    result["plots"] = benchmark_report.plots(out, {law: [r for r in every_row if r["law"] == law] for law in laws})
    (out / "report.md").write_text(benchmark_report.markdown(result, cards, units_of_scores))
    write_json_atomically(out / "scorecard.json", result)
    return result


def _write_scorecard(out, cards, units):
    import csv

    with open(out / "scorecard.csv", "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow([f"{c} [{u}]" if u else c for c, u in units.items()])
        w.writerows([["" if card[c] is None else repr(card[c]) if isinstance(card[c], float) else card[c]
                     for c in units] for card in cards])


def _write_rows_csv(path, rows, names):
    import csv

    from aotv_cosim.campaigns.store import _cell  # the campaign rows' own cell format

    with open(path, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(names)
        w.writerows([[_cell(n, r[n]) for n in names] for r in rows])
