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
import os
import tempfile
import threading
from pathlib import Path
from typing import Iterable, Mapping, Optional, Sequence, Union

from aotv_cosim.errors import InputError
from aotv_cosim.variables import describe
from aotv_cosim.output.result_types import Campaign, Result

PathLike = Union[str, os.PathLike]
"""A file or folder path."""
Overrides = Optional[Mapping[str, object]]
"""{'component.variable': value} in SI (an Enumeration by its integer or item name, a Boolean as
True/False), like `--set`."""

__all__ = ["run", "montecarlo", "benchmark", "sweep", "corridor", "describe", "Result", "Campaign", "Benchmark"]

_ONE_AT_A_TIME = threading.RLock()
"""Held by `run` and `montecarlo`: calls from several threads of one process are made one after the
other, each giving what it gives alone. FMU instantiation changes process-wide state (sys.path,
pythonfmu's interpreter state, the FMU log router) and a pythonfmu FMU's Python code holds the GIL,
so concurrent runs would risk that state and not be faster."""


def run(scenario, *, set: Overrides = None, start: Optional[float] = None, stop: Optional[float] = None,
        step: Optional[float] = None, out: Optional[PathLike] = None, plots: bool = False,
        formats: Sequence[str] = ("csv",), fmi_calls: Optional[str] = None) -> Result:
    """Run one scenario, as `aotv-cosim run` does.

    Parameters:
        scenario: a scenario file (or an .ssp archive) path, or a loaded `model.scenario.Scenario`.
        set: overrides of parameters and unconnected inputs (`Overrides`).
        start, stop, step: times in s overriding the scenario's; with start or stop overridden,
            only the expectations at the event are checked.
        out: None runs in memory and writes nothing; a folder gets the files of `aotv-cosim run`.
        plots: draw the PNG plots into `out` (needs `out`).
        formats: the time series files, "csv" and/or "parquet".
        fmi_calls: "direct" (this package's own FMUs called in this interpreter, the same
            results, faster; others through their FMI C libraries) or "c" (every FMU through its
            C library); None: "direct".

    Returns:
        a `Result`: `.timeseries` (DataFrame indexed by time in s), `.units`, `.summary`,
        `.status`, `.event`, `.expectations`, `.passed`, `.outcome`.

    Raises:
        errors.InputError: bad input, with the command line's one-line message.
    """
    from aotv_cosim.output.runner import simulate, write_run

    if out is None and plots:
        raise InputError("plots need an output folder", entry="plots", fix="give out=FOLDER, or plots=False")
    with _ONE_AT_A_TIME:  # loading may build FMUs into the shared cache: in the lock too
        loaded = _scenario(scenario, set, start, stop, step)
        _check_fmi_calls(fmi_calls)
        if out is None:
            return Result(*simulate(loaded, fmi_calls=fmi_calls))
        return Result(*write_run(loaded, out, make_plots=plots, formats=formats, fmi_calls=fmi_calls),
                      out=Path(out))


def montecarlo(scenario, runs: int, *, workers: Optional[int] = None, seed: int = 0, scheduler=None,
               out: Optional[PathLike] = None, set: Overrides = None, start: Optional[float] = None,
               stop: Optional[float] = None, keep_series: bool = False, fmi_calls: Optional[str] = None) -> Campaign:
    """Run `runs` dispersed runs of a scenario over its declared dispersions (`aotv-cosim montecarlo`).

    Parameters:
        scenario: a scenario file, or a loaded Scenario (run from its file: every worker loads it).
        runs: the number of runs.
        workers: local processes; default one per CPU this process may use (the command line's
            default is 1).
        seed: the campaign seed; run k's draws depend only on it and k, not on workers or backend.
        scheduler: a Dask scheduler address or distributed.Client instead of local processes.
        out: the campaign folder (rows.csv, rows.parquet, summary.json, plots), or None for a
            temporary one that is removed.
        set, start, stop: as for `run`.
        keep_series: also keep every run's recorded signals (about 200 rows a run) in
            out/series.parquet and draw trajectories.png.
        fmi_calls: as for `run`; the rows do not depend on it.

    Returns:
        a `Campaign`: `.rows` (one row per run, units in `.units`), `.statistics`, `.summary`.
    """
    import pandas as pd

    from aotv_cosim.campaigns import run_campaign
    from aotv_cosim.campaigns.backends import usable_cores
    from aotv_cosim.model.scenario import Scenario

    _check_fmi_calls(fmi_calls)
    path = scenario.path if isinstance(scenario, Scenario) else Path(scenario)
    if workers is None:
        workers = usable_cores()
    with _ONE_AT_A_TIME, tempfile.TemporaryDirectory(prefix="aotv_mc_") as tmp:
        folder = Path(out) if out is not None else Path(tmp)
        summary = run_campaign(path, runs, folder, workers=workers, seed=seed, scheduler=scheduler,
                               sets=set or None, start=start, stop=stop, progress=False,
                               make_plots=out is not None, keep_series=keep_series, fmi_calls=fmi_calls)
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


def benchmark(scenario_set: PathLike, laws: Iterable[PathLike] = (), *, runs: int = 1000,
              workers: Optional[int] = None, seed: int = 0, scheduler=None, out: Optional[PathLike] = None,
              reuse: bool = True, fmi_calls: Optional[str] = None) -> Benchmark:
    """Fly every law of a scenario set and your own laws through the same dispersions
    (`aotv-cosim benchmark`).

    Parameters:
        scenario_set: a folder of scenarios (one law each), one scenario file, or a shipped set's name.
        laws: wiring or scenario files of your own laws.
        runs: runs per law.
        workers, seed, scheduler: as for `montecarlo`.
        out: the output folder, or None for a temporary one.
        reuse: laws whose scenario, FMUs, dispersions, seed and runs are unchanged since an
            earlier benchmark are not flown again (their stored rows are reused); False flies all.
        fmi_calls: as for `run`; the rows do not depend on it.

    Returns:
        a `Benchmark`: `.scorecard` (one row per law) and `.rows` (every run) as DataFrames.
    """
    import pandas as pd
    import pyarrow.parquet as pq

    from aotv_cosim.campaigns.backends import usable_cores
    from aotv_cosim.campaigns.benchmark import run_benchmark

    _check_fmi_calls(fmi_calls)
    with tempfile.TemporaryDirectory(prefix="aotv_bench_") as tmp:
        folder = Path(out) if out is not None else Path(tmp)
        result = run_benchmark(scenario_set, runs, folder, workers=workers or usable_cores(), seed=seed,
                               scheduler=scheduler, progress=False, laws=[str(p) for p in laws],
                               reuse=reuse, fmi_calls=fmi_calls)
        table = pq.read_table(folder / "rows.parquet")
    rows = table.to_pandas()
    rows.attrs["units"] = {field.name: (field.metadata or {}).get(b"unit", b"").decode() for field in table.schema}
    scorecard = pd.DataFrame(result["scorecard"]).set_index("law")
    scorecard.attrs["units"] = dict(result["units"])
    return Benchmark(scorecard, rows, result, Path(out) if out is not None else None)


def sweep(scenario: PathLike, grids: Union[Mapping[str, Iterable[float]], Iterable[str]], *,
          workers: Optional[int] = None, set: Overrides = None, out: Optional[PathLike] = None):
    """Fly a scenario at every combination of parameter values (`aotv-cosim sweep`).

    Parameters:
        scenario: a scenario file.
        grids: {"comp.var": values} (SI), or strings "comp.var=LOW:HIGH:N".
        workers: as for `montecarlo`; set: as for `run`.
        out: a folder for sweep.csv/.parquet/.json and sweep.png, or None (nothing kept).

    Returns:
        a pandas DataFrame, one row per point (the parameters, status, outcome class and
        metrics, exit state, extrema), units in `.attrs["units"]`.
    """
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


def corridor(scenario: PathLike, *, lift_to_drag: float, tolerance: float = 100.0,
             bracket: Sequence[float] = (-0.08, -0.002), out: Optional[PathLike] = None) -> dict:
    """The theoretical entry corridor of a scenario whose runs are classified (`aotv-cosim corridor`).

    Parameters:
        scenario: a scenario file that declares an outcome.
        lift_to_drag: the L/D flown at full lift up and full lift down.
        tolerance: the bisection stops when a run's apogee error is within this many m of the
            capture band's edge.
        bracket: the entry flight-path angles searched (steep, shallow), rad.
        out: a folder for corridor.json, corridor.png and the two scenarios flown, or None.

    Returns:
        a dict: the entry flight-path angles (rad) bounding capture at full lift up ("steep")
        and full lift down ("shallow"), "width_rad", "width_deg", and each bisection's runs
        ("points": (gamma0, apogee error)). See `aotv_cosim.campaigns.corridor`.
    """
    from aotv_cosim.campaigns.corridor import run_corridor

    with tempfile.TemporaryDirectory(prefix="aotv_corridor_") as tmp:
        return run_corridor(scenario, Path(out) if out is not None else Path(tmp), lift_to_drag, tolerance,
                            tuple(bracket))


def _check_fmi_calls(fmi_calls):
    """Refuse an fmi_calls other than None, "c" and "direct" (InputError)."""
    if fmi_calls not in (None, "c", "direct"):
        raise InputError(f"unknown fmi_calls {fmi_calls!r}", entry="fmi_calls", fix='give "c" or "direct"')


def _scenario(scenario, sets, start, stop, step):
    """A loaded Scenario with the overrides applied (a path is loaded with them, its FMUs built
    when missing or stale)."""
    from aotv_cosim.model.scenario import Scenario, check_times
    from aotv_cosim.simulation.loading import load_scenario
    from aotv_cosim.model.system import with_values
    from aotv_cosim.fmu.build import built_fmu

    if not isinstance(scenario, Scenario):
        return load_scenario(scenario, sets, step, start, stop, fmus=built_fmu)
    changed = {}
    if sets:
        changed["system"] = with_values(scenario.system, sets, "set=")
    if start is not None or stop is not None:
        kept = [e for e in scenario.expectations if e.at == "event"]
        changed.update(expectations=kept, skipped=scenario.skipped + [e for e in scenario.expectations
                                                                      if e not in kept])
    changed.update({k: float(v) for k, v in (("start", start), ("stop", stop), ("step", step)) if v is not None})
    if not changed:
        return scenario
    result = dataclasses.replace(scenario, **changed)
    check_times(result)
    return result
