"""Parameter sweeps: a scenario flown over a full-factorial grid of values, in parallel like a
campaign, into one tidy table.

A grid is `comp.var=LOW:HIGH:N` (N values evenly spaced from LOW to HIGH, both included) or
`comp.var=A,B,C` (the values listed), in SI; LOW above HIGH flies the values in descending order.
Several grids give every combination, at most `MAX_POINTS` points (refused before any run). Each point is
one run of the campaign worker (`worker.run_batch`, FMUs reused between runs): its row holds the
parameter values (one column each, named by the parameter), status, error, the final, minimum,
maximum and exit values of the recorded signals and, when the scenario declares
`montecarlo.outcome`, the outcome class and metrics. Written in the output folder: sweep.csv,
sweep.parquet (units in the field metadata), sweep.json (grids, units, wall time) and sweep.png.
"""

import itertools
import time
from pathlib import Path

import numpy as np

from aotv_cosim.campaigns import backends
from aotv_cosim.campaigns.campaign import batches_of
from aotv_cosim.campaigns.scenario_ref import ScenarioRef
from aotv_cosim.campaigns.store import write_parquet
from aotv_cosim.campaigns.units import column_units
from aotv_cosim.campaigns.worker import columns
from aotv_cosim.simulation import interrupts
from aotv_cosim.errors import InputError
from aotv_cosim.simulation.master import Interrupted
from aotv_cosim.output.run_files import write_json_atomically
from aotv_cosim.status import Status


MAX_POINTS = 100_000
"""Most grid points one sweep flies: above, a typo (an extra zero in N) would start a sweep of days
and allocate every point up front, so it is refused before any run."""


def parse_grid(text: str, file=None) -> tuple:
    """(parameter, values) of a grid `comp.var=LOW:HIGH:N` or `comp.var=A,B,C`; InputError
    (naming `file`, the scenario) if malformed, with N < 1 or N > MAX_POINTS."""
    name, _, spec = text.partition("=")
    fix = "write COMP.VAR=LOW:HIGH:N (e.g. vehicle.gamma0=-0.03:-0.01:9) or COMP.VAR=A,B,C"
    if not name or "." not in name or not spec:
        raise InputError(f"cannot read the grid {text!r}", file=file, entry="--grid", fix=fix)
    try:
        if ":" in spec:
            low, high, count = spec.split(":")
            if not 1 <= int(count) <= MAX_POINTS:  # checked before linspace allocates N values
                raise InputError(f"the grid {text!r} asks for {int(count)} points", file=file, entry="--grid",
                                 fix=f"give N from 1 to {MAX_POINTS}")
            values = np.linspace(float(low), float(high), int(count))
        else:
            values = np.array([float(v) for v in spec.split(",")])
    except ValueError:
        raise InputError(f"cannot read the grid {text!r}", file=file, entry="--grid", fix=fix) from None
    if not np.all(np.isfinite(values)):
        raise InputError(f"the grid {text!r} has a value that is not finite", file=file, entry="--grid", fix=fix)
    return name.strip(), [float(v) for v in values]


def check_grids(grids, file=None) -> None:
    """Refuse a parameter given by two grids (the points would silently keep only the last
    grid's value), a grid without values and more than MAX_POINTS combinations."""
    names = [name for name, _ in grids]
    twice = sorted({name for name in names if names.count(name) > 1})
    if twice:
        raise InputError(f"{', '.join(twice)} is given by several grids", file=file, entry="--grid",
                         fix="give each parameter one --grid (list its values as A,B,C)")
    empty = [name for name, values in grids if not len(values)]
    if empty:
        raise InputError(f"the grid of {empty[0]} has no value", file=file, entry="--grid",
                         fix="give at least one value per grid")
    points = int(np.prod([len(values) for _, values in grids], dtype=object))
    if points > MAX_POINTS:
        raise InputError(f"the grids make {points} points", file=file, entry="--grid",
                         fix=f"give at most {MAX_POINTS} points (fewer values per grid, or several sweeps)")


def grid_points(grids) -> list:
    """Every combination of the grids' values, [{parameter: value}], the first grid slowest."""
    names = [name for name, _ in grids]
    return [dict(zip(names, combo)) for combo in itertools.product(*(values for _, values in grids))]


def run_sweep(scenario_path, grids, out_dir, workers=1, sets=None, progress=True) -> dict:
    """Fly the scenario at every grid point (`grids`: [(parameter, values)] or grid strings);
    returns {"rows": [row dicts], "columns", "units", "parameters", "status", "wall_time_s",
    "plots"} and writes the files of the module docstring. SIGINT/SIGTERM stop it: the points
    flown by then are written, status "interrupted"."""
    scenario_path = Path(scenario_path).resolve()
    grids = [parse_grid(g, scenario_path) if isinstance(g, str) else g for g in grids]
    if not grids:
        raise InputError("no grid given", file=scenario_path, entry="--grid",
                         fix="give at least one --grid COMP.VAR=LOW:HIGH:N")
    check_grids(grids, scenario_path)
    ref = ScenarioRef.of(scenario_path, sets)
    scenario = ref.load()
    parameters = [name for name, _ in grids]
    for name in parameters:
        comp, _, var = name.partition(".")
        variable = scenario.system.components[comp].fmu.variables.get(var) if comp in scenario.system.components \
            else None
        if variable is None or variable.type != "Real" or variable.causality not in ("parameter", "input"):
            raise InputError(f"{name} is not a Real parameter of the system", file=scenario_path, entry="--grid",
                             fix="sweep a parameter or start value (`aotv-cosim describe SCENARIO` lists them)")
    names = columns(scenario)
    keep = parameters + [n for n in names if n != "run" and not n.startswith("dispersed.")]
    units = {**{p: scenario.system.variable(p).unit for p in parameters},
             **{n: u for n, u in column_units(scenario, names).items() if n in keep}}
    points = grid_points(grids)
    work = list(enumerate(points))
    t0 = time.perf_counter()
    found = {}
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(work), unit="run", desc="sweep")
    status = Status.COMPLETED
    with interrupts.deferred():
        source = backends.local(ref, batches_of(work, workers), workers, names)
        try:
            for rows in source:
                for row in rows:
                    found[row["run"]] = {**points[row["run"]], **{n: row[n] for n in keep if n not in parameters}}
                if bar is not None:
                    bar.update(len(rows))
                if interrupts.received():
                    raise Interrupted(interrupts.name())
        except Interrupted:
            status = Status.INTERRUPTED  # the points flown so far are written below
        finally:
            source.close()
            if bar is not None:
                bar.close()
    rows = [found[k] for k in sorted(found)]
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    write_parquet(rows, keep, out / "sweep.parquet", units)
    _write_csv(out / "sweep.csv", rows, keep, units)
    result = {"status": status.value, "scenario": str(scenario_path), "parameters": parameters, "grids": dict(grids),
              "runs": len(rows), "points": len(points), "wall_time_s": time.perf_counter() - t0, "units": units, "columns": keep}
    from aotv_cosim.campaigns.figures import sweep_plot

    result["plots"] = [sweep_plot(out, rows, parameters, units, scenario.outcome)] if rows else []
    write_json_atomically(out / "sweep.json", result)
    return {**result, "rows": rows}


def _write_csv(path, rows, names, units):
    import csv

    from aotv_cosim.campaigns.store import csv_cell

    with open(path, "w", newline="") as f:
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow([f"{n} [{units[n]}]" if units.get(n) else n for n in names])
        writer.writerows([[csv_cell(n, r[n]) for n in names] for r in rows])
