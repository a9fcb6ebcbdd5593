"""The `aotv-cosim` command: run, check, validate, describe, build-fmus, export-ssp, montecarlo,
compare, figures.

Every error the package foresees is printed as one line `error: FILE: ENTRY: CAUSE; FIX` with
exit status 2 for bad input and 1 for a failed run or failed expectations; an unforeseen error is
one line too, unless --debug asks for the traceback.
"""

import os
import signal
import sys
import time
from pathlib import Path

import click

from aotv_cosim import cli_console as console
from aotv_cosim.cli_usage import OneLineGroup, UserPath, one_line
from aotv_cosim.simulation import interrupts
from aotv_cosim.errors import AotvError, InputError, SimulationError, ValidationFailed
from aotv_cosim.paths import writable_file, writable_folder
from aotv_cosim.status import Status

DEFAULT_OUT = Path("results")


class _Context:
    debug = False


def _fail(exc):
    lines = exc.problems if isinstance(exc, ValidationFailed) else [exc]
    for line in lines:
        click.echo(f"error: {one_line(line)}", err=True)
    sys.exit(exc.exit_status)


def _closed_pipe():
    """The reader of stdout has gone (`aotv-cosim run ... | head`): end quietly with 141 (128 +
    SIGPIPE, what a shell shows for a writer killed by the signal). stdout and stderr are pointed at
    /dev/null first, so neither a last message nor the interpreter's final flush meets the pipe."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    for stream in (sys.stdout, sys.stderr):
        try:
            os.dup2(devnull, stream.fileno())
        except (OSError, ValueError):  # a stream without a descriptor (a test runner's)
            pass
    sys.exit(128 + signal.SIGPIPE)


def _guard(function):
    """Run a command body, turning exceptions into one-line errors."""
    try:
        return function()
    except BrokenPipeError:
        _closed_pipe()
    except AotvError as exc:
        if _Context.debug:
            raise
        _fail(exc)
    except Exception as exc:  # unforeseen: still one line, traceback only on request
        if _Context.debug:
            raise
        click.echo(f"error: {type(exc).__name__}: {one_line(exc)} (run with --debug for the traceback)", err=True)
        sys.exit(3)


def _exit_status(status: str) -> int:
    """0 for a run, campaign or sweep `status` that completed or ended at an FMU's terminate
    request, 128 + signal number if interrupted (shell convention), else 1."""
    status = Status(status)
    if status == Status.INTERRUPTED:
        return 128 + (interrupts.received() or signal.SIGINT)
    return 0 if status.ended_cleanly else 1


@click.group(cls=OneLineGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.option("--debug", is_flag=True, help="Show tracebacks.")
@click.version_option(package_name="aotv-cosim")
def main(debug):
    """FMI co-simulation of aeroassisted orbital transfer and entry guidance."""
    _Context.debug = debug


def _run_one(scenario, out_dir, plots, formats=("csv",), fmi_calls=None):
    from aotv_cosim.output.runner import run_scenario

    bar, update = console.progress_bar(scenario)
    try:
        summary = run_scenario(scenario, out_dir, progress=update, make_plots=plots, formats=formats,
                               fmi_calls=fmi_calls)
        console.finish_bar(bar, summary, scenario.start)
    finally:
        bar.close()
    return summary, out_dir


_TIMES = [click.option("--start", type=float, help="Start time in s, overriding the scenario."),
          click.option("--stop", type=float, help="Stop time in s, overriding the scenario (then only "
                                                  "expectations at the event are checked).")]


def _time_options(command):
    """Add --start and --stop to a command."""
    for option in reversed(_TIMES):
        command = option(command)
    return command


def _step_timeout(default_text="the scenario's step_timeout, else none"):
    """The --step-timeout option (s, positive)."""
    return click.option("--step-timeout", type=click.FloatRange(min=0, min_open=True), metavar="SECONDS",
                        help=f"Wall-clock limit of one communication step: a step that takes longer (a hung FMU) "
                             f"fails the run, its rows kept [{default_text}].")


_FMI_CALLS = click.option(
    "--fmi-calls", type=click.Choice(["c", "direct"]), default=None,
    help="How the FMUs are called: direct, this package's own FMUs called in this process's Python (faster, "
         "the same results), others through their FMI C libraries; c, every FMU through its C library [direct].")
"""The --fmi-calls option of run, montecarlo and benchmark."""


def _limited(scenario, step_timeout):
    """The scenario with --step-timeout applied (when given)."""
    import dataclasses

    return scenario if step_timeout is None else dataclasses.replace(scenario, step_timeout=step_timeout)


_FORMATS = {"csv": ("csv",), "parquet": ("parquet",), "both": ("csv", "parquet")}


@main.command()
@click.argument("scenario", type=UserPath(dir_okay=False))
@click.option("--out", type=UserPath(), help="Output folder [results/<scenario>].")
@click.option("--set", "sets", multiple=True, metavar="COMP.VAR=VALUE", help="Override a value (repeatable).")
@click.option("--step", type=float, help="Communication step in s, overriding the scenario.")
@_time_options
@click.option("--format", "series_format", type=click.Choice(sorted(_FORMATS)), default="csv", show_default=True,
              help="Time series file: timeseries.csv, timeseries.parquet (units in the field metadata) or both.")
@click.option("--no-plots", is_flag=True, help="Skip the PNG plots.")
@_step_timeout()
@_FMI_CALLS
def run(scenario, out, sets, step, start, stop, series_format, no_plots, step_timeout, fmi_calls):
    """Run SCENARIO: writes timeseries.csv (or .parquet), summary.json (with the units) and plots.

    Exit status: 0 done, 1 failed run or expectations, 2 bad input, 130/143 interrupted by
    SIGINT/SIGTERM (the results up to then are kept, summary status 'interrupted')."""
    from aotv_cosim.model.documents import parse_sets
    from aotv_cosim.simulation.loading import load_scenario

    def body():
        loaded = _limited(_with_builds(lambda: load_scenario(scenario, parse_sets(sets, file=scenario), step, start, stop)),
                          step_timeout)
        out_dir = Path(out) if out else DEFAULT_OUT / Path(scenario).stem  # claimed by the runner
        summary, out_dir = _run_one(loaded, out_dir, not no_plots, _FORMATS[series_format], fmi_calls)
        console.print_summary(summary, out_dir)
        _print_outcome(summary)
        _print_fmu_traceback(summary)
        if not summary.status.ended_cleanly:
            sys.exit(_exit_status(summary.status))
        if not all(r["passed"] for r in summary.expectations):
            click.echo("error: expectations failed (see above)", err=True)
            sys.exit(1)

    with interrupts.deferred():
        _guard(body)


def _print_outcome(summary):
    """The run's class and exit-orbit figures in display units (km, m/s), when it is classified."""
    outcome = summary.outcome
    if outcome:
        def km(name):
            value = float(outcome[name])
            return f"{value / 1e3:.6g} km" if value == value else "-"

        click.echo(f"  outcome: {outcome['class']} ({outcome['reason']}); apogee {km('apogee')}, perigee "
                   f"{km('perigee')}, apogee error {km('apogee_error')}, correction dv "
                   f"{float(outcome['dv_total']):.5g} m/s (SI in summary.json)")


def _print_fmu_traceback(summary):
    """The Python traceback an FMU logged when it failed (its file and line), with --debug; else
    a hint that it is there."""
    trace = (summary.error_detail or {}).get("traceback")
    if trace and _Context.debug:
        click.echo(trace, err=True)
    elif trace:
        click.echo("  the FMU's Python traceback is in summary.json (error_detail.traceback); "
                   "--debug prints it", err=True)


@main.command()
@click.argument("paths", nargs=-1, type=UserPath(exists=True))
@click.option("--out", type=UserPath(file_okay=False), help="Base output folder [results/check].")
@_time_options
def check(paths, out, start, stop):
    """Run every scenario with expectations under PATHS [scenarios/] and compare.

    Every scenario found is loaded and validated before the first one runs; each result line
    starts with its N/M count."""
    from aotv_cosim.simulation.loading import load_scenario

    def body():
        files = []
        for p in paths or ("scenarios",):
            p = Path(p)
            if p.is_dir() and not os.access(p, os.R_OK | os.X_OK):
                raise InputError("cannot list the folder: permission denied", file=p,
                                 fix="give a folder you may read")
            files += [f for f in sorted(p.glob("*.json")) if _kind(f) == "scenario"] if p.is_dir() else [p]
        loaded = _with_builds(lambda: [load_scenario(f, start=start, stop=stop) for f in files])
        candidates = [s for s in loaded if s.expectations or s.skipped]
        writable_folder(Path(out or DEFAULT_OUT / "check"))
        failed, t0 = 0, time.perf_counter()
        for k, scenario in enumerate(candidates, 1):
            summary, _ = _run_one(scenario, Path(out or DEFAULT_OUT / "check") / scenario.path.stem, False)
            ok = summary.status.ended_cleanly and all(r["passed"] for r in summary.expectations)
            failed += not ok
            click.echo(f"[{k}/{len(candidates)}] {'PASS' if ok else 'FAIL'} {scenario.path}  ({summary.status}, "
                       f"{summary.wall_time_s:.2f} s)")
            console.print_failure(summary)
            console.print_expectations(summary.expectations)
            if summary.status == Status.INTERRUPTED:
                sys.exit(_exit_status(summary.status))
        click.echo(f"{len(candidates) - failed} passed, {failed} failed in {time.perf_counter() - t0:.1f} s")
        sys.exit(1 if failed else 0)

    with interrupts.deferred():
        _guard(body)


@main.command()
@click.argument("files", nargs=-1, required=True, type=UserPath(dir_okay=False))
def validate(files):
    """Check scenario, wiring or comparison FILES without running them."""
    from aotv_cosim.studies.compare import load_comparison
    from aotv_cosim.simulation.loading import load_scenario
    from aotv_cosim.simulation.loading import load_system
    from aotv_cosim.fmu.build import built_fmu

    loaders = {"wiring": lambda f: load_system(f, fmus=built_fmu), "scenario": load_scenario,
               "compare": load_comparison}

    def body():
        for f in files:
            kind = _kind(f)
            loaders[kind](f)
            click.echo(f"ok: {f} ({kind})")

    _guard(body)


def _with_builds(load):
    """load(), showing a message and a bar if it builds FMUs (the first use of changed sources)."""
    from aotv_cosim.fmu.build_progress import BuildProgress

    with BuildProgress():
        return load()


def _kind(path):
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


@main.command()
@click.argument("target", metavar="FMU|WIRING")
def describe(target):
    """Print the variables of an FMU (a name of this package or a .fmu file), or of every FMU of a
    WIRING, scenario or .ssp file: causality, variability, type, unit, start, declared min and
    max, description (for a wiring also the value it sets or the source of a connected input)."""
    from aotv_cosim.variables import describe as table, format_table

    _guard(lambda: click.echo(format_table(_with_builds(lambda: table(target)))))


@main.command("build-fmus")
@click.argument("sources", nargs=-1, metavar="[NAME|SOURCE.py]...")
@click.option("--out", type=UserPath(file_okay=False), help="Put the FMUs here instead of the cache.")
@click.option("--fmi", "fmi_version", type=click.Choice(["2", "3"]),
              help="FMI version of the FMUs: 2 (default) or 3; a pythonfmu3 class is always 3.")
def build_fmus(sources, out, fmi_version):
    """Build the FMUs of fmus_src, or only the given ones: names of this package or your own FMU
    sources (SOURCE.py, any folder; see docs/writing-a-guidance-law.md). Only changed sources are
    rebuilt (content hash)."""
    from aotv_cosim.fmu import build as fmu_build
    from aotv_cosim.fmu.build_progress import BuildProgress

    def body():
        refs = list(sources) or fmu_build.available_fmus()
        version = int(fmi_version) if fmi_version else None
        with BuildProgress(total=sum(fmu_build.needs_build(r, out, version) for r in refs)) as progress:
            for ref in refs:
                progress.echo(f"{fmu_build.fmu_source(ref).stem}: {fmu_build.ensure_fmu(ref, out, version)}")

    _guard(body)


@main.command()
@click.argument("scenario", type=UserPath(dir_okay=False))
@click.option("--runs", type=click.IntRange(min=1), required=True, help="Number of runs.")
@click.option("--workers", type=click.IntRange(min=1), default=1, show_default=True,
              help="Local worker processes.")
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True, help="Campaign seed.")
@click.option("--scheduler", metavar="ADDRESS", help="Run on this Dask distributed scheduler instead.")
@click.option("--out", type=UserPath(), help="Output folder [results/<scenario>-mc].")
@click.option("--resume", is_flag=True, help="Continue an interrupted campaign in --out.")
@click.option("--set", "sets", multiple=True, metavar="COMP.VAR=VALUE", help="Override a value (repeatable).")
@click.option("--keep-series", is_flag=True, help="Keep every run's recorded signals (about 200 rows a run) in "
                                                  "series.parquet and draw the trajectory overlay.")
@_time_options
@_step_timeout("the scenario's step_timeout, else 60")
@click.option("--max-rss", type=click.FloatRange(min=0, min_open=True), default=2048, show_default=True,
              metavar="MIB", help="Resident memory a local worker may use, MiB: a run that passes it is recorded "
                                  "failed and its worker replaced.")
@_FMI_CALLS
def montecarlo(scenario, runs, workers, seed, scheduler, out, resume, sets, keep_series, start, stop, step_timeout,
               max_rss, fmi_calls):
    """Run a Monte Carlo campaign of SCENARIO over its declared dispersions."""
    from aotv_cosim.campaigns.checks import check_reachable, check_resumable
    from aotv_cosim.campaigns.report import console_table
    from aotv_cosim.campaigns import run_campaign
    from aotv_cosim.model.documents import parse_sets

    def body():
        out_dir = Path(out) if out else DEFAULT_OUT / f"{Path(scenario).stem}-mc"
        if resume:
            check_resumable(out_dir)
        if scheduler:
            check_reachable(scheduler)
        summary = _with_builds(lambda: run_campaign(scenario, runs, out_dir, workers=workers, seed=seed,
                                                    scheduler=scheduler, resume=resume,
                                                    sets=parse_sets(sets, file=scenario) or None, start=start, stop=stop,
                                                    keep_series=keep_series, step_timeout=step_timeout,
                                                    max_rss=max_rss * 2**20, fmi_calls=fmi_calls))
        for warning in summary["warnings"]:
            click.echo(f"warning: {warning}", err=True)
        rate = summary["runs_per_s"]
        click.echo(f"{runs} runs ({summary['runs_this_session']} this session) in {summary['wall_time_s']:.1f} s"
                   + (f", {rate:.1f} runs/s" if rate else "") + f": {summary['statuses']}")
        click.echo(console_table(summary["three_sigma"], summary["units"], summary["outcomes"]))
        click.echo(f"  rows in {out_dir / 'rows.csv'} and rows.parquet, statistics and units in summary.json,"
                   f" tables and plots in {out_dir / 'report.md'}")
        if summary["status"] == Status.INTERRUPTED:
            click.echo(f"  {summary['stop_reason']}: finished runs kept; --resume runs the others")
            sys.exit(_exit_status(summary["status"]))
        if not summary["statuses"].get(Status.COMPLETED):
            first = summary["failed"][0] if summary["failed"] else {"run": "-", "error": "no run"}
            click.echo(f"error: {scenario}: runs: none of the {runs} runs completed (run {first['run']}: "
                       f"{' '.join(str(first['error']).split())}); see the error column of rows.csv", err=True)
            sys.exit(1)

    _guard(body)


@main.command()
@click.argument("scenario_set", metavar="SET", type=UserPath())
@click.option("--law", "laws", multiple=True, type=UserPath(exists=True, dir_okay=False), metavar="FILE",
              help="Your law: a wiring (flown in SET's first scenario) or a scenario with SET's dispersions "
                   "(repeatable).")
@click.option("--runs", type=click.IntRange(min=1), default=1000, show_default=True, help="Runs per law.")
@click.option("--workers", type=click.IntRange(min=1), default=1, show_default=True,
              help="Local worker processes.")
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True, help="Campaign seed.")
@click.option("--scheduler", metavar="ADDRESS", help="Run on this Dask distributed scheduler instead.")
@click.option("--out", type=UserPath(file_okay=False), help="Output folder [results/<set>-benchmark].")
@click.option("--refly", is_flag=True, help="Fly every law, even those whose stored rows could be reused.")
@_FMI_CALLS
def benchmark(scenario_set, laws, runs, workers, seed, scheduler, out, refly, fmi_calls):
    """Fly every law (scenario) of SET (a folder, one scenario file, or a shipped set by name:
    benchmark_seed000) and each --law through the
    same dispersions; write a scorecard. A law whose scenario, FMUs, dispersions, seed and N are
    unchanged since an earlier benchmark is not flown again: its stored rows are reused."""
    from aotv_cosim.campaigns.benchmark import run_benchmark
    from aotv_cosim.campaigns.benchmark_report import console
    from aotv_cosim.campaigns.checks import check_reachable

    def body():
        out_dir = Path(out) if out else DEFAULT_OUT / f"{Path(scenario_set).stem}-benchmark"
        writable_folder(out_dir)
        if scheduler:
            check_reachable(scheduler)
        result = _with_builds(lambda: run_benchmark(scenario_set, runs, out_dir, workers=workers, seed=seed,
                                                    scheduler=scheduler, laws=laws, echo=click.echo,
                                                    reuse=not refly, fmi_calls=fmi_calls))
        click.echo(console(result["scorecard"], result["units"]))
        flown = [law for law, info in result["laws"].items() if not info["reused"]]
        click.echo(f"{len(result['scorecard'])} laws x {runs} runs ({len(flown)} flown now in "
                   f"{result['wall_time_s']:.1f} s, {len(result['scorecard']) - len(flown)} reused); scorecard.csv,"
                   f" rows.csv, rows.parquet, report.md and plots in {out_dir}")

    with interrupts.deferred():
        _guard(body)


@main.command()
@click.argument("scenario", type=UserPath(dir_okay=False))
@click.option("--grid", "grids", multiple=True, required=True, metavar="COMP.VAR=LOW:HIGH:N",
              help="Values of a parameter: N evenly spaced from LOW to HIGH, or A,B,C (SI; repeatable: every "
                   "combination is flown).")
@click.option("--workers", type=click.IntRange(min=1), default=1, show_default=True,
              help="Local worker processes.")
@click.option("--set", "sets", multiple=True, metavar="COMP.VAR=VALUE", help="Override a value (repeatable).")
@click.option("--out", type=UserPath(file_okay=False), help="Output folder [results/<scenario>-sweep].")
def sweep(scenario, grids, workers, sets, out):
    """Fly SCENARIO at every point of the grids: sweep.csv/.parquet (one row per point: the parameters,
    outcome, exit state and extrema, units in the header), sweep.json and sweep.png."""
    from aotv_cosim.campaigns.units import display
    from aotv_cosim.campaigns.sweep import run_sweep
    from aotv_cosim.model.documents import parse_sets

    def body():
        out_dir = Path(out) if out else DEFAULT_OUT / f"{Path(scenario).stem}-sweep"
        writable_folder(out_dir)
        result = _with_builds(lambda: run_sweep(scenario, grids, out_dir, workers=workers,
                                                sets=parse_sets(sets) or None))
        units = result["units"]
        shown = result["parameters"] + [c for c in ("outcome", "outcome.apogee_error", "outcome.dv_total")
                                        if c in units]
        click.echo("  ".join(f"{c} [{display(c, units[c])[0]}]" if units[c] else c for c in shown))
        for row in result["rows"]:
            cells = [row[c] if isinstance(row[c], str) else f"{float(row[c]) * display(c, units[c])[1]:.6g}"
                     for c in shown]
            click.echo("  ".join(cells))
        click.echo(f"{result['runs']} runs in {result['wall_time_s']:.1f} s; sweep.csv, sweep.parquet (SI) and "
                   f"sweep.png in {out_dir}")
        if result["status"] == Status.INTERRUPTED:
            click.echo(f"  interrupted after {result['runs']} of {result['points']} points: those are kept")
            sys.exit(_exit_status(result["status"]))

    with interrupts.deferred():
        _guard(body)


@main.command()
@click.argument("scenario", type=UserPath(dir_okay=False))
@click.option("--lift-to-drag", type=float, required=True, metavar="L/D",
              help="Lift-to-drag ratio flown at full lift up and down (the vehicle's capability).")
@click.option("--tolerance", type=float, default=100.0, show_default=True,
              help="Bisection stops when a run's apogee error is this close to the band edge (m).")
@click.option("--bracket", type=(float, float), default=(-0.08, -0.002), show_default=True,
              metavar="STEEP SHALLOW", help="Entry flight-path angles searched (rad).")
@click.option("--out", type=UserPath(file_okay=False), help="Output folder [results/<scenario>-corridor].")
def corridor(scenario, lift_to_drag, tolerance, bracket, out):
    """The theoretical entry corridor of SCENARIO: the entry flight-path angles bounding capture at
    full lift up (steep bound) and full lift down (shallow bound), by bisection on the capture
    band; corridor.json, corridor.png."""
    import math

    from aotv_cosim.campaigns.corridor import run_corridor

    def body():
        out_dir = Path(out) if out else DEFAULT_OUT / f"{Path(scenario).stem}-corridor"
        writable_folder(out_dir)
        r = _with_builds(lambda: run_corridor(scenario, out_dir, lift_to_drag, tolerance, bracket))
        for bound, how in (("steep", "full lift up"), ("shallow", "full lift down")):
            b = r[bound]
            click.echo(f"{bound} bound ({how}, L/D {lift_to_drag:g}): gamma0 = {b['gamma0']:.6g} rad "
                       f"({math.degrees(b['gamma0']):.4f} deg), apogee error {b['apogee_error'] / 1e3:+.4f} km "
                       f"(edge {b['edge'] / 1e3:+g} km, {b['runs']} runs)")
        click.echo(f"corridor width {r['width_rad']:.6g} rad ({r['width_deg']:.4f} deg); nominal gamma0 "
                   f"{r['nominal_gamma0']:g} rad; corridor.json and corridor.png in {out_dir}")

    with interrupts.deferred():
        _guard(body)


@main.command("export-ssp")
@click.argument("scenario", type=UserPath(dir_okay=False))
@click.option("-o", "--out", "out", required=True, type=UserPath(dir_okay=False),
              help="The .ssp archive to write.")
@click.option("--set", "sets", multiple=True, metavar="COMP.VAR=VALUE", help="Override a value (repeatable).")
@click.option("--step", type=float, help="Communication step in s, overriding the scenario.")
@click.option("--fmi", "fmi_version", type=click.Choice(["2", "3"]), default="2", show_default=True,
              help="FMI version of this package's FMUs in the archive (other .fmu files are copied as they are).")
def export_ssp(scenario, out, sets, step, fmi_version):
    """Write SCENARIO's system as an SSP archive (FMUs, SSD, SSV, default experiment)."""
    from aotv_cosim.model.documents import parse_sets
    from aotv_cosim.simulation.loading import load_scenario
    from aotv_cosim.ssp.export import default_experiment, export_ssp as write_ssp

    def body():
        loaded = load_scenario(scenario, parse_sets(sets, file=scenario), step)
        path = write_ssp(loaded, writable_file(out, "--out"), fmi_version=int(fmi_version))
        start, stop, every = default_experiment(path)  # the stop the system reaches (ssp.experiment)
        click.echo(f"{path}: {len(loaded.system.components)} components, "
                   f"{len(loaded.system.connections)} connections, "
                   f"{start:g}..{stop:g} s by {every:g} s")

    _guard(body)


@main.command()
@click.argument("comparison", default="scenarios/aotv_compare.json", type=UserPath(dir_okay=False))
@click.option("--out", type=UserPath(file_okay=False), help="Output folder [results/<comparison>].")
@click.option("--no-plots", is_flag=True, help="Skip the overlaid plots.")
def compare(comparison, out, no_plots):
    """Fly every guidance law of COMPARISON [scenarios/aotv_compare.json] through the same
    (dispersed) atmosphere; write comparison.csv and comparison.png, print the table."""
    from aotv_cosim.studies.compare import format_table, load_comparison, run_comparison

    def body():
        loaded = load_comparison(comparison)
        out_dir = writable_folder(Path(out) if out else DEFAULT_OUT / Path(comparison).stem)
        table = run_comparison(loaded, out_dir, progress=lambda law: click.echo(f"flying {law}", err=True),
                               make_plots=not no_plots)
        click.echo(format_table(table))
        click.echo(f"table in {out_dir / 'comparison.csv'}")

    _guard(body)


@main.group()
def figures():
    """Draw a seed's figures (the documents' plots, from this package's runs)."""


def _shipped(name):
    from aotv_cosim.studies.shipped import scenario

    return str(scenario(name))


@figures.command("seed000")
@click.option("--out", type=UserPath(file_okay=False), default="results/seed000_figures", show_default=True)
@click.option("--scenarios", type=UserPath(file_okay=False), help="Folder of the seed-000 scenarios "
              "[the shipped scenarios].")
def figures_seed000(out, scenarios):
    """Seed-000 thesis figures: altitude, speed, flight-path angle, lift command and heating against
    time for every law (nominal entry and atmosphere), and the Table 8.1 comparison (table and
    figure); prints the table (runs 8 laws twice and 11 scenarios, about a minute)."""
    from aotv_cosim.studies.seed000_figures import make_all

    def body():
        files, table = _with_builds(lambda: make_all(Path(out), scenarios,
                                                     progress=lambda name: click.echo(f"flying {name}", err=True)))
        click.echo(table)
        for path in files:
            click.echo(path)

    _guard(body)


@figures.command("seed001")
@click.option("--out", type=UserPath(file_okay=False), default="results/seed001_figures", show_default=True)
@click.option("--scenario", type=UserPath(dir_okay=False), help="The guided run "
              "[the shipped plane_change_mae_guided.json].")
def figures_seed001(out, scenario):
    """Seed-001 report figures 3.4-3.19: gamma, speed, costates, lambda, bank, altitude; guided against optimal."""
    from aotv_cosim.studies.plane_change_plots import make_all

    guided = scenario or _shipped("plane_change_mae_guided.json")
    _guard(lambda: [click.echo(Path(out) / name) for name in _with_builds(lambda: make_all(Path(out), guided))])


@figures.command("seed002")
@click.argument("run_dir", required=False, type=UserPath(exists=True, file_okay=False))
@click.option("--out", type=UserPath(file_okay=False), help="Output folder [RUN_DIR, or "
              "results/seed002_figures without it].")
@click.option("--scenario", type=UserPath(dir_okay=False), help="Without RUN_DIR, the run to make first "
              "[the shipped entry_ideal_combined.json].")
def figures_seed002(run_dir, out, scenario):
    """Seed-002 paper figures 1-6 of a finished entry-tracking run in RUN_DIR (from `aotv-cosim run
    scenarios/entry_*.json`): ground track, errors against Mach, alpha and bank with their bands,
    altitude, drag. Without RUN_DIR the ideal-plant combined case is run first (into OUT/run)."""
    from aotv_cosim.studies.entry_plots import plot

    def body():
        folder, target = run_dir, out
        if run_dir is None:
            from aotv_cosim.output.runner import run_scenario
            from aotv_cosim.simulation.loading import load_scenario

            target = Path(out or "results/seed002_figures")
            folder = target / "run"
            loaded = _with_builds(lambda: load_scenario(scenario or _shipped("entry_ideal_combined.json")))
            summary = run_scenario(loaded, folder, make_plots=False)
            if summary.status != Status.COMPLETED:
                raise SimulationError(f"the run failed: {summary.error}", file=str(loaded.path),
                                      fix=f"see {folder / 'summary.json'}")
        for path in plot(folder, target):
            click.echo(path)

    _guard(body)


@figures.command("seed003")
@click.option("--out", type=UserPath(file_okay=False), default="results/seed003_report", show_default=True)
def figures_seed003(out):
    """Seed-003 nominal glide, alpha per elevator law and the saturation study; prints the metrics table
    (runs the scenarios/shuttle_*.json systems, about a minute)."""
    from aotv_cosim.studies.shuttle_report import main as report

    _guard(lambda: _with_builds(lambda: report(out)))
