"""The Python API: `run` a scenario, run a Monte Carlo campaign (`montecarlo`), compare guidance laws
(`benchmark`), `sweep` parameters, find the entry `corridor`, `describe` FMUs, `build_fmus`,
`validate` files and `export_ssp`.

Each function takes keyword options, builds the command's options object (`aotv_cosim.options`:
every value checked there, as for the command line) and hands it to `execute`, which the command
line calls too with the object its parser built: one front door. Bad input raises
`aotv_cosim.errors.InputError` with the same one-line message the command line prints.

Everything returns pandas DataFrames with the unit of every column (`.units`, and the
DataFrame's `attrs["units"]`), taken from the FMUs' modelDescriptions. Nothing here installs a
signal handler or exits the interpreter: a run stopped by Ctrl-C (KeyboardInterrupt) returns a
Result with status 'interrupted', and any number of calls can be made in one interpreter (a
notebook). Calls from several threads are made one at a time (`_ONE_AT_A_TIME`, held by `execute`).
"""

import dataclasses
import errno
import os
import tempfile
import threading
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

from aotv_cosim.errors import InputError
from aotv_cosim.options import (
    BenchmarkOptions,
    BuildOptions,
    CampaignOptions,
    CheckOptions,
    CompareOptions,
    CorridorOptions,
    DescribeOptions,
    ExportOptions,
    RunOptions,
    SweepOptions,
    ValidateOptions,
)
from aotv_cosim.options.commands import DEFAULT_MAX_RSS_MIB
from aotv_cosim.output.result_types import Campaign, Result

PathLike = str | os.PathLike
"""A file or folder path."""
Overrides = Mapping[str, object] | None
"""{'component.variable': value} in SI (an Enumeration by its integer or item name, a Boolean as
True/False), like `--set`."""

__all__ = [
    "Benchmark",
    "Campaign",
    "Result",
    "benchmark",
    "build_fmus",
    "corridor",
    "describe",
    "execute",
    "export_ssp",
    "montecarlo",
    "run",
    "sweep",
    "validate",
]

_ONE_AT_A_TIME = threading.RLock()
"""Held by every call (`execute`): calls from several threads of one process are made one after the
other, each giving what it gives alone. FMU instantiation and building change process-wide state
(sys.path, pythonfmu's interpreter state, the FMU log router, the FMU cache) and a pythonfmu FMU's
Python code holds the GIL, so concurrent calls would risk that state and not be faster."""


def execute(options, **hooks):
    """Do the command of `options` (an object of `aotv_cosim.options`), one call at a time; what it
    returns is what the command's function of this module returns. `hooks` are the command line's
    ways of showing progress (see each `_do_*`)."""
    try:
        do = _COMMANDS[type(options)]
    except KeyError:
        raise InputError(f"not an options object of aotv_cosim.options: {type(options).__name__}",
                         entry="options", fix="give RunOptions, CampaignOptions, ... (aotv_cosim.options)") from None
    with _ONE_AT_A_TIME:
        try:
            return do(options, **hooks)
        except OSError as exc:  # a result file a full or read-only disk cut (those written whole are kept whole)
            if exc.errno not in _DISK_FULL:
                raise
            from aotv_cosim.output.run_files import OutputError

            raise OutputError(Path(exc.filename or getattr(options, "out", None) or "."), exc) from exc


_DISK_FULL = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS, errno.EIO)
"""The errno of a write that the disk refused: a command meeting one ends with one line (exit 1)."""


def run(scenario, *, set: Overrides = None, start: float | None = None, stop: float | None = None,
        step: float | None = None, out: PathLike | None = None, plots: bool = False,
        formats: str | Sequence[str] = ("csv",), step_timeout: float | None = None,
        fmi_calls: str | None = None) -> Result:
    """Run one scenario, as `aotv-cosim run` does.

    Parameters:
        scenario: a scenario file (or an .ssp archive) path, or a loaded `model.scenario.Scenario`.
        set: overrides of parameters and unconnected inputs (`Overrides`).
        start, stop, step: times in s overriding the scenario's; with start or stop overridden,
            only the expectations at the event are checked.
        out: None runs in memory and writes nothing; a folder gets the files of `aotv-cosim run`.
        plots: draw the PNG plots into `out` (needs `out`).
        formats: the time series files, "csv" and/or "parquet" (one name alone is one format).
        step_timeout: wall-clock limit of one step, s (None: the scenario's, else none).
        fmi_calls: "direct" (this package's own FMUs called in this interpreter, the same
            results, faster; others through their FMI C libraries) or "c" (every FMU through its
            C library); None: "direct".

    Returns:
        a `Result`: `.timeseries` (DataFrame indexed by time in s), `.units`, `.summary`,
        `.status`, `.event`, `.expectations`, `.passed`, `.outcome`.

    Raises:
        errors.InputError: bad input, with the command line's one-line message.
    """
    return execute(RunOptions.of(scenario=scenario, sets=set, start=start, stop=stop, step=step, out=out, plots=plots,
                                 formats=formats, step_timeout=step_timeout, fmi_calls=fmi_calls))


def montecarlo(scenario, runs: int, *, workers: int | None = None, seed: int = 0, scheduler=None,
               out: PathLike | None = None, resume: bool = False, set: Overrides = None,
               start: float | None = None, stop: float | None = None, keep_series: bool = False,
               step_timeout: float | None = None, max_rss: float | None = DEFAULT_MAX_RSS_MIB,
               fmi_calls: str | None = None) -> Campaign:
    """Run `runs` dispersed runs of a scenario over its declared dispersions (`aotv-cosim montecarlo`).

    Parameters:
        scenario: a scenario file, or a loaded Scenario (run from its file: every worker loads it).
        runs: the number of runs (1 to `options.checks.MAX_RUNS`).
        workers: local processes; default one per CPU this process may use (the command line's
            default is 1).
        seed: the campaign seed; run k's draws depend only on it and k, not on workers or backend.
        scheduler: a Dask scheduler address or distributed.Client instead of local processes.
        out: the campaign folder (rows.csv, rows.parquet, summary.json, plots), or None for a
            temporary one that is removed.
        resume: continue the interrupted campaign in `out`.
        set, start, stop: as for `run`.
        keep_series: also keep every run's recorded signals (about 200 rows a run) in
            out/series.parquet and draw trajectories.png.
        step_timeout: wall-clock limit of one step, s (None: the scenario's, else 60 s).
        max_rss: resident memory a local worker may use, MiB (None: no limit).
        fmi_calls: as for `run`; the rows do not depend on it.

    Returns:
        a `Campaign`: `.rows` (one row per run, units in `.units`), `.statistics`, `.summary`.
    """
    return execute(CampaignOptions.of(scenario=scenario, runs=runs, workers=workers, seed=seed, scheduler=scheduler,
                                      out=out, resume=resume, sets=set, start=start, stop=stop, keep_series=keep_series,
                                      step_timeout=step_timeout, max_rss=max_rss, fmi_calls=fmi_calls))


@dataclasses.dataclass
class Benchmark:
    """A guidance benchmark: `scorecard` (one row per law, index law) and `rows` (every run of
    every law, a `law` column) as DataFrames with their units in `.attrs["units"]`; in a set with
    an oracle, the scorecard's `role` (the oracle, the bound, or a law) and `dv_penalty_p50`,
    `dv_penalty_p99.865` (m/s), the rows' `oracle.dv_total` and `oracle.dv_penalty` (m/s, nan
    unless both the law and the oracle captured the run: `campaigns.oracle_score`); `result`:
    the scorecard.json dict (which laws were flown now and which reused, wall time, the laws whose
    runs all failed, status "interrupted" if a SIGINT/SIGTERM stopped it: then only the laws done
    by then and no rows); `out`: the output folder or None."""

    scorecard: Any
    rows: Any
    result: dict
    out: Path | None = None

    @property
    def failed_laws(self) -> list:
        """The laws none of whose runs completed."""
        return list(self.result.get("failed_laws", []))

    def __repr__(self):
        return f"<Benchmark {len(self.scorecard)} laws x {self.result['runs']} runs, seed {self.result['seed']}>"


def benchmark(scenario_set: PathLike, laws: PathLike | Iterable[PathLike] = (), *, runs: int = 1000,
              workers: int | None = None, seed: int = 0, scheduler=None, out: PathLike | None = None,
              reuse: bool = True, step_timeout: float | None = None,
              max_rss: float | None = DEFAULT_MAX_RSS_MIB, fmi_calls: str | None = None) -> Benchmark:
    """Fly every law of a scenario set and your own laws through the same dispersions
    (`aotv-cosim benchmark`).

    Parameters:
        scenario_set: a folder of scenarios (one law each), one scenario file, or a shipped set's
            name (benchmark_seed000, benchmark_aerocapture/afe, benchmark_aerocapture/aotv).
        laws: wiring or scenario files of your own laws (one path alone is one law).
        runs: runs per law.
        workers, seed, scheduler, step_timeout, max_rss, fmi_calls: as for `montecarlo`.
        out: the output folder, or None for a temporary one.
        reuse: laws whose scenario, FMUs, dispersions, seed and runs are unchanged since an
            earlier benchmark are not flown again (their stored rows are reused); False flies all.

    Returns:
        a `Benchmark`: `.scorecard` (one row per law) and `.rows` (every run) as DataFrames.
    """
    return execute(BenchmarkOptions.of(scenario_set=scenario_set, laws=laws, runs=runs, workers=workers, seed=seed,
                                       scheduler=scheduler, out=out, reuse=reuse, step_timeout=step_timeout,
                                       max_rss=max_rss, fmi_calls=fmi_calls))


def sweep(scenario: PathLike, grids: Mapping[str, Iterable[float]] | Iterable[str], *,
          workers: int | None = None, scheduler=None, set: Overrides = None, out: PathLike | None = None,
          step_timeout: float | None = None, max_rss: float | None = DEFAULT_MAX_RSS_MIB,
          fmi_calls: str | None = None):
    """Fly a scenario at every combination of parameter values (`aotv-cosim sweep`).

    Parameters:
        scenario: a scenario file.
        grids: {"comp.var": values} (SI), or strings "comp.var=LOW:HIGH:N"; every value is checked
            as `set` would check it (declared min/max, connected inputs refused) before any run.
        workers, scheduler, step_timeout, max_rss, fmi_calls: as for `montecarlo`; set: as for `run`.
        out: a folder for sweep.csv/.parquet/.json and sweep.png, or None (nothing kept).

    Returns:
        a pandas DataFrame, one row per point (the parameters, status, outcome class and
        metrics, exit state, extrema), units in `.attrs["units"]`, the sweep's summary (status,
        runs, points, wall time) in `.attrs["sweep"]`.
    """
    return execute(SweepOptions.of(scenario=scenario, grids=grids, workers=workers, scheduler=scheduler, sets=set,
                                   out=out, step_timeout=step_timeout, max_rss=max_rss, fmi_calls=fmi_calls))


def corridor(scenario: PathLike, *, lift_to_drag: float | None = None, aim: str = "target",
             angle_tolerance: float = 1e-6, tolerance: float | None = None, step: float | None = None,
             bracket: Sequence[float] | None = None, set: Overrides = None, out: PathLike | None = None,
             workers: int | None = None, scheduler=None, step_timeout: float | None = None,
             max_rss: float | None = DEFAULT_MAX_RSS_MIB,
             fmi_calls: str | None = None) -> dict:
    """The theoretical entry corridor of a scenario whose runs are classified (`aotv-cosim corridor`).

    Parameters:
        scenario: a scenario file that declares an outcome.
        lift_to_drag: the L/D flown at full lift up and down by a vehicle steered by its lift
            acceleration (required there, finite, > 0); leave it out for a bank-angle vehicle,
            which flies its own C_L/C_D at sigma = 0 and 180 deg.
        aim: "target" (both bounds exit on the target apogee) or "band" (on the capture band's
            lower and upper edges).
        angle_tolerance: a bisection ends when its gamma0 bracket is this narrow, rad.
        tolerance: a bisection also ends when a run lands this close to the aim, m (None: never).
        step: the communication step of the passes, s (None: the scenario's, at most 0.1 s).
        bracket: the entry flight-path angles searched (steep, shallow), rad, both in (-pi/2, 0)
            (None: each bound searched outward from the scenario's entry).
        set: overrides of the passes' parameters (`Overrides`), e.g. {"atmosphere.profile_sigma": 0}
            for the aerocapture sets' atmosphere without its random profile.
        out: a folder for corridor.json, corridor.png and the two scenarios flown, or None.
        workers: local processes (default one per usable core; 2 search both bounds side by
            side, more are not used); scheduler, step_timeout, max_rss, fmi_calls: as for `montecarlo`.

    Returns:
        a dict: the entry flight-path angles (rad) of the "steep" (full lift up) and "shallow"
        (full lift down) bounds, "width_rad", "width_deg", the plant read from the wiring
        ("plant", "control", "removed", "lift_to_drag") and each bisection's runs ("points":
        (gamma0, apogee error)). See `aotv_cosim.campaigns.corridor`.
    """
    return execute(CorridorOptions.of(scenario=scenario, lift_to_drag=lift_to_drag, aim=aim,
                                      angle_tolerance=angle_tolerance, tolerance=tolerance, step=step, bracket=bracket,
                                      sets=set, out=out, workers=workers, scheduler=scheduler,
                                      step_timeout=step_timeout, max_rss=max_rss, fmi_calls=fmi_calls))


def describe(target):
    """The variables of an FMU (a name of this package, a .fmu or a .py source) or of every FMU of a
    wiring, scenario or .ssp file, or of a loaded System or Scenario (`aotv-cosim describe`): a
    DataFrame, one row per variable (causality, variability, type, unit, start, min, max,
    description; for a system also the component and the value it sets)."""
    return execute(DescribeOptions.of(target=target))


def build_fmus(sources: PathLike | Iterable[PathLike] = (), *, out: PathLike | None = None,
               fmi_version: int | None = None) -> dict:
    """Build the FMUs of fmus_src (or only `sources`: names of this package or your .py FMU
    sources, one alone is one) into the cache, or as NAME.fmu into `out` (`aotv-cosim build-fmus`);
    only changed sources are rebuilt. fmi_version: 2 or 3 (None: 2, or 3 for a pythonfmu3 class).
    Returns {name: FMU path}."""
    return execute(BuildOptions.of(sources=sources, out=out, fmi_version=fmi_version))


def validate(files: PathLike | Iterable[PathLike], *, benchmark: PathLike | None = None) -> list:
    """Check scenario, wiring, comparison or .ssp files without running them (`aotv-cosim
    validate`): [(file, kind)] when all are sound; InputError (ValidationFailed for several
    problems of one file) at the first that is not. With `benchmark` (a set: a folder, a scenario
    or a shipped set's name, e.g. "benchmark_aerocapture/afe") each file is a law's wiring or
    scenario, also checked against the set's contract (`campaigns.contract`: the plant, the command,
    the signals the set reads and the values it disperses), every missing piece named in the file."""
    return execute(ValidateOptions.of(files=files, benchmark=benchmark))


def export_ssp(scenario: PathLike, out: PathLike, *, set: Overrides = None, step: float | None = None,
               fmi_version: int = 2) -> Path:
    """Write the system of `scenario` as the SSP archive `out` (`aotv-cosim export-ssp`), this
    package's FMUs as FMI `fmi_version` (2 or 3); returns its path."""
    return execute(ExportOptions.of(scenario=scenario, out=out, sets=set, step=step, fmi_version=fmi_version))


# --- what each command does, given its checked options ----------------------------------------


def _do_run(options: RunOptions, progress=None) -> Result:
    """progress(scenario): given the loaded scenario, returns update(t), told the simulation time
    (s) as the run goes."""
    from aotv_cosim.output.runner import simulate, write_run

    scenario = _loaded(options)
    update = progress(scenario) if progress is not None else None
    if options.out is None:
        return Result(*simulate(scenario, progress=update, fmi_calls=options.fmi_calls))
    return Result(*write_run(scenario, options.out, update, make_plots=options.plots, formats=options.formats,
                             fmi_calls=options.fmi_calls), out=Path(options.out))


def _loaded(options: RunOptions):
    """The options' scenario loaded with their overrides applied once (a path is loaded with them,
    its FMUs built when missing or stale; a loaded Scenario is copied with them)."""
    from aotv_cosim.model.scenario import Scenario, check_times
    from aotv_cosim.model.system import with_values
    from aotv_cosim.simulation.loading import load_scenario

    scenario, sets = options.scenario, options.overrides or None
    start, stop, step = options.start, options.stop, options.step
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario, sets, step, start, stop)
    else:
        changed: dict[str, Any] = {}
        if sets:
            changed["system"] = with_values(scenario.system, sets, f"{scenario.path} (with --set)")
        if start is not None or stop is not None:
            kept = [e for e in scenario.expectations if e.at == "event"]
            changed.update(expectations=kept, skipped=scenario.skipped + [e for e in scenario.expectations
                                                                          if e not in kept])
        changed.update({k: v for k, v in (("start", start), ("stop", stop), ("step", step)) if v is not None})
        if changed:
            scenario = dataclasses.replace(scenario, **changed)
            check_times(scenario)
    timeout = options.step_timeout
    return scenario if timeout is None else dataclasses.replace(scenario, step_timeout=timeout)


def _do_montecarlo(options: CampaignOptions) -> Campaign:
    import pandas as pd

    from aotv_cosim.campaigns import run_campaign
    from aotv_cosim.campaigns.checks import check_reachable, check_resumable

    if options.resume:
        check_resumable(options.out)
    if isinstance(options.scheduler, str):
        check_reachable(options.scheduler)
    with tempfile.TemporaryDirectory(prefix="aotv_mc_") as tmp:
        flown = options if options.out is not None else options.replace(out=tmp, plots=False)
        summary = run_campaign(flown)
        rows = pd.read_parquet(Path(options.out or tmp) / "rows.parquet")
    return Campaign(summary, rows, out=options.out)


def _do_benchmark(options: BenchmarkOptions, echo=None) -> Benchmark:
    """echo(text): told which laws are flown and which reused."""
    import pandas as pd
    import pyarrow.parquet as pq

    from aotv_cosim.campaigns.benchmark import run_benchmark
    from aotv_cosim.campaigns.checks import check_reachable

    if isinstance(options.scheduler, str):
        check_reachable(options.scheduler)
    with tempfile.TemporaryDirectory(prefix="aotv_bench_") as tmp:
        flown = options if options.out is not None else options.replace(out=tmp)
        result = run_benchmark(flown, echo)
        if result["status"] == "interrupted":
            rows = pd.DataFrame()
        else:
            table = pq.read_table(Path(options.out or tmp) / "rows.parquet")
            rows = table.to_pandas()
            rows.attrs["units"] = {f.name: (f.metadata or {}).get(b"unit", b"").decode() for f in table.schema}
    scorecard = pd.DataFrame(result["scorecard"], columns=list(result["units"])).set_index("law")
    scorecard.attrs["units"] = dict(result["units"])
    return Benchmark(scorecard, rows, result, options.out)


def _do_sweep(options: SweepOptions):
    import pandas as pd

    from aotv_cosim.campaigns.checks import check_reachable
    from aotv_cosim.campaigns.sweep import run_sweep

    if isinstance(options.scheduler, str):
        check_reachable(options.scheduler)
    with tempfile.TemporaryDirectory(prefix="aotv_sweep_") as tmp:
        result = run_sweep(options if options.out is not None else options.replace(out=tmp))
    frame = pd.DataFrame(result.pop("rows"), columns=result["columns"])
    frame.attrs["units"] = dict(result["units"])
    frame.attrs["sweep"] = result
    return frame


def _do_corridor(options: CorridorOptions) -> dict:
    from aotv_cosim.campaigns.checks import check_reachable
    from aotv_cosim.campaigns.corridor import run_corridor

    if isinstance(options.scheduler, str):
        check_reachable(options.scheduler)
    with tempfile.TemporaryDirectory(prefix="aotv_corridor_") as tmp:
        return run_corridor(options if options.out is not None else options.replace(out=tmp))


def _do_describe(options: DescribeOptions):
    from aotv_cosim.variables import describe as table

    return table(options.target)


def _do_build(options: BuildOptions, progress=None) -> dict:
    """progress: a `fmu.build_progress.BuildProgress` told each FMU as it is ready (its `echo`)."""
    import contextlib

    from aotv_cosim.fmu import build as fmu_build
    from aotv_cosim.output.outdir import claimed

    refs = [str(s) for s in options.sources] or fmu_build.available_fmus()
    names = {ref: fmu_build.fmu_source(ref).stem for ref in refs}  # an unknown name or source: refused first
    built = {}
    with contextlib.ExitStack() as stack:
        if options.out is not None:  # NAME.fmu there are written only over FMUs this package built
            out = Path(options.out)
            theirs = [f"{name}.fmu" for name in names.values() if fmu_build.built_hash(out / f"{name}.fmu") is None]
            stack.enter_context(claimed(out, theirs))
        for ref in refs:
            built[names[ref]] = path = fmu_build.ensure_fmu(ref, options.out, options.fmi_version)
            if progress is not None:
                progress.echo(f"{names[ref]}: {path}")
    return built


def _do_validate(options: ValidateOptions, each=None, contract=None) -> list:
    """each(file, kind): told each file found sound; contract(needs): told the contract of
    `options.benchmark` (`campaigns.contract`) when a set is given."""
    from aotv_cosim.fmu.build import built_fmu
    from aotv_cosim.simulation.loading import load_scenario, load_system
    from aotv_cosim.studies.compare import load_comparison

    loaders: dict[str, Callable] = {"wiring": lambda f: load_system(f, fmus=built_fmu), "scenario": load_scenario,
                                    "compare": load_comparison}
    needs = None
    if options.benchmark is not None:
        from aotv_cosim.campaigns import benchmark
        from aotv_cosim.campaigns.contract import of_set

        needs = of_set(benchmark.scenarios_of(options.benchmark))
        if contract is not None:
            contract(needs)
    found = []
    for f in options.files:
        kind = document_kind(f)
        loaded = loaders[kind](f)
        if needs is not None:
            _check_law(needs, kind, loaded, f, options.benchmark)
        found.append((f, kind))
        if each is not None:
            each(f, kind)
    return found


def _check_law(needs, kind, loaded, file, set_name) -> None:
    """The loaded law `file` (a wiring or scenario) checked against its set's contract `needs`."""
    from aotv_cosim.campaigns import contract

    if kind == "wiring":
        contract.check(needs, loaded, file, set_name)
    elif kind == "scenario":
        contract.check(needs, loaded.system, file, set_name, entry_prefix=f"system ({Path(loaded.system.path).name}): ")
    else:
        raise InputError("a comparison file is no law of a benchmark set", file=file, entry="--benchmark",
                         fix="give the law's wiring or scenario file")


def _do_export(options: ExportOptions, loaded=None) -> Path:
    """loaded(scenario): given the loaded scenario."""
    from aotv_cosim.paths import writable_file
    from aotv_cosim.simulation.loading import load_scenario
    from aotv_cosim.ssp.export import check_replaceable
    from aotv_cosim.ssp.export import export_ssp as write_ssp

    check_replaceable(options.out)  # before the FMUs are built for it
    scenario = load_scenario(options.scenario, options.overrides or None, options.step)
    if loaded is not None:
        loaded(scenario)
    return write_ssp(scenario, writable_file(options.out, "--out"), fmi_version=options.fmi_version)


def _do_check(options: CheckOptions, each=None, run=None) -> list:
    """Every scenario with expectations under `options.paths`, loaded (and so validated) before
    the first runs, then run into OUT/<scenario>; returns [(scenario, RunSummary)], stopping after
    an interrupted run. each(k, total, scenario, summary): told each finished run; run(scenario,
    folder): makes a run and returns its RunSummary (default `output.runner.run_scenario`, no plots)."""
    from aotv_cosim.output.outdir import written
    from aotv_cosim.output.runner import run_scenario
    from aotv_cosim.paths import writable_folder
    from aotv_cosim.simulation.loading import load_scenario
    from aotv_cosim.status import Status

    files = []
    for p in options.paths:
        if p.is_dir() and not os.access(p, os.R_OK | os.X_OK):
            raise InputError("cannot list the folder: permission denied", file=p, fix="give a folder you may read")
        if not p.is_dir():
            files.append(p)
            continue
        ours = written(p)  # not the files a command wrote there (a run's summary.json)
        files += [f for f in sorted(p.glob("*.json")) if f.name not in ours and document_kind(f) == "scenario"]
    loaded = [load_scenario(f, start=options.start, stop=options.stop) for f in files]
    candidates = [s for s in loaded if s.expectations or s.skipped]
    base = writable_folder(options.out or Path("results") / "check")
    run = run or (lambda scenario, folder: run_scenario(scenario, folder, make_plots=False))
    done = []
    for k, scenario in enumerate(candidates, 1):
        summary = run(scenario, base / scenario.path.stem)
        done.append((scenario, summary))
        if each is not None:
            each(k, len(candidates), scenario, summary)
        if summary.status == Status.INTERRUPTED:
            break
    return done


def _do_compare(options: CompareOptions, progress=None) -> list:
    """progress(law): told each law before it is flown."""
    from aotv_cosim.output.outdir import claimed
    from aotv_cosim.studies.compare import load_comparison, run_comparison

    loaded = load_comparison(options.comparison)
    out = options.out or Path("results") / Path(options.comparison).stem
    with claimed(out, ("comparison.csv", "comparison.png")):
        return run_comparison(loaded, out, progress=progress, make_plots=options.plots)


def document_kind(path) -> str:
    """The kind of document `path` is: named by its "$schema" (wiring, compare, scenario), else
    'wiring' if it has components or connections, else 'scenario'.

    A file that cannot be read or parsed, or is no regular file (a FIFO would block), counts as
    a scenario: its loader reports the problem."""
    from aotv_cosim.model.documents import strict_json
    from aotv_cosim.paths import MAX_DOCUMENT_BYTES, regular_file

    try:
        regular_file(path, max_bytes=MAX_DOCUMENT_BYTES)
        doc = strict_json(Path(path).read_text(encoding="utf-8"))
    except (InputError, OSError, ValueError, RecursionError):
        return "scenario"
    if not isinstance(doc, dict):
        return "scenario"
    named = [k for k in ("wiring", "compare", "scenario") if f"{k}.schema.json" in str(doc.get("$schema", ""))]
    if named:
        return named[0]
    return "wiring" if "components" in doc or "connections" in doc else "scenario"


_COMMANDS: dict[type, Callable] = {
    RunOptions: _do_run, CampaignOptions: _do_montecarlo, BenchmarkOptions: _do_benchmark,
    SweepOptions: _do_sweep, CorridorOptions: _do_corridor, DescribeOptions: _do_describe,
    BuildOptions: _do_build, ValidateOptions: _do_validate, ExportOptions: _do_export,
    CheckOptions: _do_check, CompareOptions: _do_compare}
"""The implementation of each command, by the type of its options."""
