"""The Python API: `run` a scenario, run a Monte Carlo campaign (`montecarlo`), compare guidance laws
(`benchmark`), `describe` FMUs.

Everything returns pandas DataFrames with the unit of every column (`.units`, and the
DataFrame's `attrs["units"]`), taken from the FMUs' modelDescriptions. Nothing here installs a
signal handler or exits the interpreter: a run stopped by Ctrl-C (KeyboardInterrupt) returns a
Result with status 'interrupted', and any number of calls can be made in one interpreter (a
notebook). Bad input raises `aotv_cosim.errors.InputError` with the same one-line message the
command line prints. Calls from several threads are made one at a time (`_ONE_AT_A_TIME`).
"""

import dataclasses
import tempfile
import threading
from pathlib import Path

from aotv_cosim.errors import InputError
from aotv_cosim.variables import describe
from aotv_cosim.engine.result import Campaign, Result

__all__ = ["run", "montecarlo", "benchmark", "sweep", "corridor", "describe", "Result", "Campaign", "Benchmark"]

_ONE_AT_A_TIME = threading.RLock()
"""Held by `run` and `montecarlo`: calls from several threads of one process are made one after the
other, each giving what it gives alone. FMU instantiation changes process-wide state (sys.path,
pythonfmu's interpreter state, the FMU log router) and a pythonfmu FMU's Python code holds the GIL,
so concurrent runs would risk that state and not be faster."""


def run(scenario, *, set=None, start=None, stop=None, step=None, out=None, plots=False,
        formats=("csv",)) -> Result:
    """Run one scenario: a scenario file (or .ssp) path, or a loaded `scenario.Scenario`.

    set: {'comp.var': value} overrides (SI); start, stop, step: times in s overriding the
    scenario's (with start or stop overridden, only the expectations at the event are checked).
    out: None runs in memory and writes nothing; a folder gets the files of `aotv-cosim run`
    (the time series in `formats`, "csv" and/or "parquet", summary.json, and the PNG plots if
    `plots`).
    """
    from aotv_cosim.engine.runner import simulate, write_run

    if out is None and plots:
        raise InputError("plots need an output folder", entry="plots", fix="give out=FOLDER, or plots=False")
    with _ONE_AT_A_TIME:  # loading may build FMUs into the shared cache: in the lock too
        loaded = _scenario(scenario, set, start, stop, step)
        if out is None:
            return Result(*simulate(loaded))
        return Result(*write_run(loaded, out, make_plots=plots, formats=formats), out=Path(out))


def montecarlo(scenario, runs, *, workers=None, seed=0, scheduler=None, out=None, set=None,
               start=None, stop=None, keep_series=False) -> Campaign:
    """Run `runs` dispersed runs of a scenario file over its declared dispersions.

    workers: local processes (default: one per CPU this process may use); scheduler: a Dask
    scheduler address or distributed.Client instead; seed: the campaign seed (run k's draws
    depend only on it and k). out: the campaign folder (rows.csv, rows.parquet, summary.json,
    plots), or None for a temporary one that is removed. A loaded Scenario is run from its file,
    since every worker loads it itself. keep_series: also keep every run's recorded signals
    (about 200 rows a run) in out/series.parquet and draw trajectories.png. Returns the rows as a
    DataFrame with units and the statistics.
    """
    import pandas as pd

    from aotv_cosim.campaigns import run_campaign
    from aotv_cosim.campaigns.backends import usable_cores
    from aotv_cosim.engine.scenario import Scenario

    path = scenario.path if isinstance(scenario, Scenario) else Path(scenario)
    if workers is None:
        workers = usable_cores()
    with _ONE_AT_A_TIME, tempfile.TemporaryDirectory(prefix="aotv_mc_") as tmp:
        folder = Path(out) if out is not None else Path(tmp)
        summary = run_campaign(path, runs, folder, workers=workers, seed=seed, scheduler=scheduler,
                               sets=set or None, start=start, stop=stop, progress=False,
                               make_plots=out is not None, keep_series=keep_series)
        rows = pd.read_parquet(folder / "rows.parquet")
    return Campaign(summary, rows, out=Path(out) if out is not None else None)


@dataclasses.dataclass
class Benchmark:
    """A guidance benchmark: `scorecard` (one row per law, index law) and `rows` (every run of
    every law, a `law` column) as DataFrames with their units in `.attrs["units"]`; `result`:
    the scorecard.json dict (which laws were flown now and which reused, wall time); `out`: the
    output folder or None."""

    scorecard: object
    rows: object
    result: dict
    out: Path = None

    def __repr__(self):
        return f"<Benchmark {len(self.scorecard)} laws x {self.result['runs']} runs, seed {self.result['seed']}>"


def benchmark(scenario_set, laws=(), *, runs=1000, workers=None, seed=0, scheduler=None, out=None,
              reuse=True) -> Benchmark:
    """Fly every law of `scenario_set` (a folder of scenarios, one law each, or one scenario
    file) and each of `laws` (wiring or scenario files of your own laws) through the set's
    dispersions, `runs` runs each; see `aotv-cosim benchmark`. Laws whose scenario, FMUs,
    dispersions, seed and runs are unchanged since an earlier benchmark are not flown again (their
    stored rows are reused, unless reuse=False). out: the output folder, or None for a temporary
    one."""
    import pandas as pd
    import pyarrow.parquet as pq

    from aotv_cosim.campaigns.backends import usable_cores
    from aotv_cosim.campaigns.benchmark import run_benchmark

    with tempfile.TemporaryDirectory(prefix="aotv_bench_") as tmp:
        folder = Path(out) if out is not None else Path(tmp)
        result = run_benchmark(scenario_set, runs, folder, workers=workers or usable_cores(), seed=seed,
                               scheduler=scheduler, progress=False, laws=[str(p) for p in laws],
                               reuse=reuse)
        table = pq.read_table(folder / "rows.parquet")
    rows = table.to_pandas()
    rows.attrs["units"] = {field.name: (field.metadata or {}).get(b"unit", b"").decode() for field in table.schema}
    scorecard = pd.DataFrame(result["scorecard"]).set_index("law")
    scorecard.attrs["units"] = dict(result["units"])
    return Benchmark(scorecard, rows, result, Path(out) if out is not None else None)


def sweep(scenario, grids, *, workers=None, set=None, out=None):
    """Fly `scenario` (a file) at every combination of `grids` ({"comp.var": values} or strings
    "comp.var=LOW:HIGH:N"): one tidy DataFrame, a row per point (the parameters, status, outcome
    class and metrics, exit state, extrema), units in `.attrs["units"]`. out: a folder for
    sweep.csv/.parquet/.json and sweep.png, or None (nothing kept)."""
    import pandas as pd

    from aotv_cosim.campaigns.backends import usable_cores
    from aotv_cosim.campaigns.sweep import run_sweep

    specs = ([(name, [float(v) for v in values]) for name, values in grids.items()] if isinstance(grids, dict)
             else list(grids))
    with tempfile.TemporaryDirectory(prefix="aotv_sweep_") as tmp:
        result = run_sweep(scenario, specs, Path(out) if out is not None else Path(tmp),
                           workers=workers or usable_cores(), sets=set, progress=False)
    frame = pd.DataFrame(result["rows"], columns=result["columns"])
    frame.attrs["units"] = dict(result["units"])
    return frame


def corridor(scenario, *, lift_to_drag: float, tolerance: float = 100.0, bracket=(-0.08, -0.002),
             out=None) -> dict:
    """The theoretical entry corridor of `scenario` (a file whose runs are classified): the entry
    flight-path angles (rad) bounding capture at full lift up ("steep") and full lift down
    ("shallow") at the stated `lift_to_drag`, found by bisection until a run's apogee error is
    within `tolerance` m of the capture band's edge; "width_rad", "width_deg" and the runs of
    each bisection ("points": (gamma0, apogee error)). See `aotv_cosim.campaigns.corridor`. out:
    a folder for corridor.json, corridor.png and the two scenarios flown, or None."""
    from aotv_cosim.campaigns.corridor import run_corridor

    with tempfile.TemporaryDirectory(prefix="aotv_corridor_") as tmp:
        return run_corridor(scenario, Path(out) if out is not None else Path(tmp), lift_to_drag, tolerance,
                            tuple(bracket))


def _scenario(scenario, sets, start, stop, step):
    """A loaded Scenario with the overrides applied (a path is loaded with them)."""
    from aotv_cosim.engine.scenario import Scenario, _check_times, load_scenario
    from aotv_cosim.engine.system import load_system

    if not isinstance(scenario, Scenario):
        return load_scenario(scenario, sets, step, start, stop)
    changed = {}
    if sets:
        system = scenario.system
        values = {f"{c.name}.{k}": v for c in system.components.values() for k, v in c.parameters.items()}
        changed["system"] = load_system(system.path, {**values, **sets}, overrides_file="set=")
    if start is not None or stop is not None:
        kept = [e for e in scenario.expectations if e.at == "event"]
        changed.update(expectations=kept, skipped=scenario.skipped + [e for e in scenario.expectations
                                                                      if e not in kept])
    changed.update({k: float(v) for k, v in (("start", start), ("stop", stop), ("step", step)) if v is not None})
    if not changed:
        return scenario
    result = dataclasses.replace(scenario, **changed)
    _check_times(result)
    return result
