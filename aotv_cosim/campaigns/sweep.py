"""Parameter sweeps: a scenario flown over a full-factorial grid of values, in parallel like a
campaign, into one tidy table.

A grid is `comp.var=LOW:HIGH:N` (N values evenly spaced from LOW to HIGH, both included) or
`comp.var=A,B,C` (the values listed), in SI; LOW above HIGH flies the values in descending order.
Several grids give every combination, at most `options.checks.MAX_POINTS` points (refused before any
run, with every value checked as `--set` checks it: `options.SweepOptions`). Each point is
one run of the campaign worker (`worker.run_batch`, FMUs reused between runs): its row holds the
parameter values (one column each, named by the parameter), status, error, the final, minimum,
maximum and exit values of the recorded signals and, when the scenario declares
`montecarlo.outcome`, the outcome class and metrics. Written in the output folder: sweep.csv,
sweep.parquet (units in the field metadata), sweep.json (grids, units, wall time) and sweep.png.
"""

import itertools
import time
from pathlib import Path
from typing import cast

from aotv_cosim.campaigns import backends
from aotv_cosim.campaigns.scenario_ref import ScenarioRef
from aotv_cosim.campaigns.store import write_parquet
from aotv_cosim.campaigns.units import column_units
from aotv_cosim.campaigns.worker import columns
from aotv_cosim.options import SweepOptions
from aotv_cosim.output.outdir import claimed
from aotv_cosim.output.run_files import write_json_atomically
from aotv_cosim.simulation import interrupts
from aotv_cosim.simulation.master import FMI_CALLS_DEFAULT, Interrupted
from aotv_cosim.status import Status

SWEEP_OUTPUTS = ("sweep.csv", "sweep.parquet", "sweep.parquet.part", "sweep.json", "sweep.json.part", "sweep.png")
"""The files a sweep writes in its folder."""


def grid_points(grids) -> list:
    """Every combination of the grids' values, [{parameter: value}], the first grid slowest."""
    names = [name for name, _ in grids]
    return [dict(zip(names, combo)) for combo in itertools.product(*(values for _, values in grids))]


def run_sweep(options: SweepOptions) -> dict:
    """Fly `options.scenario` at every point of `options.grids` (checked before any run as `--set`
    checks its values, `SweepOptions.check_values`), on the backend of the options (local workers
    or Dask); returns {"rows": [row dicts], "columns", "units", "parameters", "status",
    "wall_time_s", "plots"} and writes the files of the module docstring into `options.out`.
    SIGINT/SIGTERM stop it: the points flown by then are written, status "interrupted"."""
    scenario_path = Path(options.scenario).resolve()
    ref = ScenarioRef.of(scenario_path, options.overrides)
    scenario = ref.load()
    options.check_values(scenario.system)
    parameters = [name for name, _ in options.grids]
    names = columns(scenario)
    keep = parameters + [n for n in names if n != "run" and not n.startswith("dispersed.")]
    units = {**{p: scenario.system.variable(p).unit for p in parameters},
             **{n: u for n, u in column_units(scenario, names).items() if n in keep}}
    points = grid_points(options.grids)
    with interrupts.deferred(), claimed(options.out, SWEEP_OUTPUTS):
        rows, status, wall = _fly(ref, scenario, options, points, names, parameters, keep)
        out = Path(cast(Path, options.out))  # the API gives a temporary folder when the caller gives none
        write_parquet(rows, keep, out / "sweep.parquet", units)
        _write_csv(out / "sweep.csv", rows, keep, units)
        result = {"status": status.value, "scenario": str(scenario_path), "parameters": parameters,
                  "grids": {name: list(values) for name, values in options.grids}, "runs": len(rows),
                  "points": len(points), "wall_time_s": wall,
                  "backend": "local" if options.scheduler is None else "dask", "workers": options.workers,
                  "fmi_calls": options.fmi_calls or FMI_CALLS_DEFAULT,
                  "limits": {"step_timeout_s": options.step_limit(scenario), "max_rss_mib": options.max_rss},
                  "units": units, "columns": keep}
        from aotv_cosim.campaigns.figures import sweep_plot

        result["plots"] = [sweep_plot(out, rows, parameters, units, scenario.outcome)] if rows else []
        write_json_atomically(out / "sweep.json", result)
    return {**result, "rows": rows}


def _fly(ref, scenario, options, points, names, parameters, keep):
    """(rows sorted by point, status, wall time in s) of the grid `points` flown on the options'
    backend."""
    t0 = time.perf_counter()
    found = {}
    backend = backends.opened(options, options.step_limit(scenario), names)  # refused (a scheduler) before a bar
    bar = None
    if options.progress:
        from tqdm import tqdm

        bar = tqdm(total=len(points), unit="run", desc="sweep")
    status = Status.COMPLETED
    interrupted = True
    try:
        for rows in backends.stream(backend, ref, enumerate(points), len(points)):
            for row in rows:
                found[row["run"]] = {**points[row["run"]], **{n: row[n] for n in keep if n not in parameters}}
            if bar is not None:
                bar.update(len(rows))
            if interrupts.received():
                raise Interrupted(interrupts.name())
        interrupted = False
    except Interrupted:
        status = Status.INTERRUPTED  # the points flown so far are written
    finally:
        backend.close(interrupted)
        if bar is not None:
            bar.close()
    return [found[k] for k in sorted(found)], status, time.perf_counter() - t0


def _write_csv(path, rows, names, units):
    import csv

    from aotv_cosim.campaigns.store import csv_cell

    with open(path, "w", newline="") as f:
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow([f"{n} [{units[n]}]" if units.get(n) else n for n in names])
        writer.writerows([[csv_cell(n, r[n]) for n in names] for r in rows])
