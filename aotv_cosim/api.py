"""The Python API: `run` a scenario, run a Monte Carlo campaign (`montecarlo`), `describe` FMUs.

Everything returns pandas DataFrames with the unit of every column (`.units`, and the
DataFrame's `attrs["units"]`), taken from the FMUs' modelDescriptions. Nothing here installs a
signal handler or exits the interpreter: a run stopped by Ctrl-C (KeyboardInterrupt) returns a
Result with status 'interrupted', and any number of calls can be made in one interpreter (a
notebook). Bad input raises `aotv_cosim.engine.errors.InputError` with the same one-line message the
command line prints. Calls from several threads are made one at a time (`_ONE_AT_A_TIME`).
"""

import dataclasses
import tempfile
import threading
from pathlib import Path

from aotv_cosim.engine.errors import InputError
from aotv_cosim.fmu.describe import describe
from aotv_cosim.engine.result import Campaign, Result

__all__ = ["run", "montecarlo", "describe", "Result", "Campaign"]

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
               start=None, stop=None) -> Campaign:
    """Run `runs` dispersed runs of a scenario file over its declared dispersions.

    workers: local processes (default: one per CPU this process may use); scheduler: a Dask
    scheduler address or distributed.Client instead; seed: the campaign seed (run k's draws
    depend only on it and k). out: the campaign folder (rows.csv, rows.parquet, summary.json,
    plots), or None for a temporary one that is removed. A loaded Scenario is run from its file,
    since every worker loads it itself. Returns the rows as a DataFrame with units and the
    statistics.
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
                               make_plots=out is not None)
        rows = pd.read_parquet(folder / "rows.parquet")
    return Campaign(summary, rows, out=Path(out) if out is not None else None)


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
