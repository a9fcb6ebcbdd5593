"""The `aotv-cosim` command: run, check, validate, describe, build-fmus, export-ssp, montecarlo,
compare, figures.

Every error the package foresees is printed as one line `error: FILE: ENTRY: CAUSE; FIX` with
exit status 2 for bad input and 1 for a failed run or failed expectations; an unforeseen error is
one line too, unless --debug asks for the traceback.
"""

import contextlib
import os
import signal
import sys
import time
from pathlib import Path

import click

from aotv_cosim import cli_console as console
from aotv_cosim.cli_usage import OneLineGroup, UserPath, one_line
from aotv_cosim.errors import AotvError, SimulationError, ValidationFailed
from aotv_cosim.simulation import interrupts
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
        with contextlib.suppress(OSError, ValueError):  # a stream without a descriptor (a test runner's)
            os.dup2(devnull, stream.fileno())
    sys.exit(128 + signal.SIGPIPE)


def _guard(function):
    """Run a command body, turning exceptions into one-line errors."""
    try:
        return function()
    except BrokenPipeError:
        _closed_pipe()
    except KeyboardInterrupt:  # SIGINT/SIGTERM outside a run's deferred handling, or while loading, building
        if _Context.debug:
            raise
        click.echo(f"error: interrupted by {interrupts.name() or 'SIGINT'}; the files written so far are kept",
                   err=True)
        sys.exit(128 + (interrupts.received() or signal.SIGINT))
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
    # SIGTERM, like SIGINT, raises where the command is (once), so its cleanup runs: no child
    # process or temporary folder is left; runs and campaigns defer both (`interrupts.deferred`)
    click.get_current_context().with_resource(interrupts.raising_once())


def _run_one(scenario, out_dir, plots=False):
    """A run of `check`, into out_dir, with its progress bar; returns its RunSummary."""
    from aotv_cosim.output.runner import run_scenario

    bar, update = console.progress_bar(scenario)
    try:
        summary = run_scenario(scenario, out_dir, progress=update, make_plots=plots)
        console.finish_bar(bar, summary, scenario.start)
    finally:
        bar.close()
    return summary


def _execute(options, **hooks):
    """The API's `execute` of `options`, showing a message and a bar if it builds FMUs (the first
    use of changed sources)."""
    from aotv_cosim.api import execute
    from aotv_cosim.fmu.build_progress import BuildProgress

    with BuildProgress():
        return execute(options, **hooks)


def _default_out(out, scenario, suffix=""):
    """--out, else results/<scenario's name><suffix> (the command line always writes its results)."""
    return Path(out) if out else DEFAULT_OUT / f"{Path(str(scenario)).stem}{suffix}"


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
    return click.option("--step-timeout", type=float, metavar="SECONDS",
                        help=f"Wall-clock limit of one communication step: a step that takes longer (a hung FMU) "
                             f"fails the run, its rows kept [{default_text}].")


_FMI_CALLS = click.option(
    "--fmi-calls", metavar="direct|c", default=None,
    help="How the FMUs are called: direct, this package's own FMUs called in this process's Python (faster, "
         "the same results), others through their FMI C libraries; c, every FMU through its C library [direct].")
"""The --fmi-calls option of the commands that run."""


def _runs_options(command):
    """Add the options of how runs are made (montecarlo, benchmark, sweep, corridor): --workers,
    --scheduler, --step-timeout, --max-rss, --fmi-calls."""
    from aotv_cosim.options.commands import DEFAULT_MAX_RSS_MIB

    for option in reversed([
            click.option("--workers", type=int, default=1, show_default=True, help="Local worker processes."),
            click.option("--scheduler", metavar="ADDRESS", help="Run on this Dask distributed scheduler instead."),
            _step_timeout("the scenario's step_timeout, else 60"),
            click.option("--max-rss", type=float, default=DEFAULT_MAX_RSS_MIB, show_default=True, metavar="MIB",
                         help="Resident memory a local worker may use, MiB: a run that passes it is recorded "
                              "failed and its worker replaced."),
            _FMI_CALLS]):
        command = option(command)
    return command


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
    from aotv_cosim.options import RunOptions

    def body():
        options = RunOptions.of(scenario=scenario, out=_default_out(out, scenario),
                                sets=parse_sets(sets, file=scenario), step=step, start=start, stop=stop,
                                formats=_FORMATS[series_format], plots=not no_plots, step_timeout=step_timeout,
                                fmi_calls=fmi_calls)
        bar = _RunBar()
        try:
            summary = _execute(options, progress=bar.begin).run_summary
            bar.finish(summary)
        finally:
            bar.close()
        console.print_summary(summary, options.out)
        _print_outcome(summary)
        _print_fmu_traceback(summary)
        if not summary.status.ended_cleanly:
            sys.exit(_exit_status(summary.status))
        if not all(r["passed"] for r in summary.expectations):
            click.echo("error: expectations failed (see above)", err=True)
            sys.exit(1)

    with interrupts.deferred():
        _guard(body)


class _RunBar:
    """A run's progress bar (`cli_console.progress_bar`), made when the scenario is loaded (`begin`,
    the API's progress hook: it spans the scenario's times)."""

    def __init__(self):
        self.bar, self.start = None, 0.0

    def begin(self, scenario):
        self.bar, update = console.progress_bar(scenario)
        self.start = scenario.start
        return update

    def finish(self, summary):
        if self.bar is not None:
            console.finish_bar(self.bar, summary, self.start)

    def close(self):
        if self.bar is not None:
            self.bar.close()


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
    """The Python traceback an FMU logged when it failed: its last frames (the user's file and line)
    and the exception, compactly; all of it with --debug."""
    from aotv_cosim.output.tracebacks import short_traceback

    detail = summary.error_detail or {}
    trace = detail.get("traceback")
    if not trace:
        return
    if _Context.debug:
        click.echo(trace, err=True)
        return
    lines = short_traceback(trace, detail.get("source"))
    click.echo(f"  {detail.get('component') or 'the FMU'} raised (last frames; the whole traceback is in "
               "summary.json error_detail.traceback):", err=True)
    for line in lines:
        click.echo(f"    {line}", err=True)


@main.command()
@click.argument("paths", nargs=-1, type=UserPath(exists=True))
@click.option("--out", type=UserPath(file_okay=False), help="Base output folder [results/check].")
@_time_options
def check(paths, out, start, stop):
    """Run every scenario with expectations under PATHS [scenarios/] and compare.

    Every scenario found is loaded and validated before the first one runs; each result line
    starts with its N/M count."""
    from aotv_cosim.options import CheckOptions

    def body():
        options = CheckOptions.of(paths=paths or ("scenarios",), out=out, start=start, stop=stop)
        t0 = time.perf_counter()
        failed = []

        def each(k, total, scenario, summary):
            ok = summary.status.ended_cleanly and all(r["passed"] for r in summary.expectations)
            failed.extend([] if ok else [scenario])
            click.echo(f"[{k}/{total}] {'PASS' if ok else 'FAIL'} {scenario.path}  ({summary.status}, "
                       f"{summary.wall_time_s:.2f} s)")
            console.print_failure(summary)
            console.print_expectations(summary.expectations)

        done = _execute(options, each=each, run=_run_one)
        if done and done[-1][1].status == Status.INTERRUPTED:
            sys.exit(_exit_status(done[-1][1].status))
        click.echo(f"{len(done) - len(failed)} passed, {len(failed)} failed in {time.perf_counter() - t0:.1f} s")
        sys.exit(1 if failed else 0)

    with interrupts.deferred():
        _guard(body)


@main.command()
@click.argument("files", nargs=-1, type=UserPath(dir_okay=False))
@click.option("--benchmark", "benchmark_set", metavar="SET",
              help="Check each file as a law of the benchmark SET (a folder, or a shipped set's name, e.g. "
                   "benchmark_aerocapture/afe) against the set's contract; with no FILE, print the contract.")
def validate(files, benchmark_set):
    """Check scenario, wiring or comparison FILES without running them."""
    from aotv_cosim.campaigns.contract import markdown
    from aotv_cosim.options import ValidateOptions

    def contract(needs):
        if not files:
            click.echo(f"What a law of {benchmark_set} must provide:\n\n{markdown(needs)}", nl=False)

    _guard(lambda: _execute(ValidateOptions.of(files=files, benchmark=benchmark_set),
                            each=lambda f, kind: click.echo(f"ok: {f} ({kind}" + (f", a law of {benchmark_set})"
                                                                                  if benchmark_set else ")")),
                            contract=contract))


@main.command()
@click.argument("target", metavar="FMU|WIRING")
def describe(target):
    """Print the variables of an FMU (a name of this package or a .fmu file), or of every FMU of a
    WIRING, scenario or .ssp file: causality, variability, type, unit, start, declared min and
    max, description (for a wiring also the value it sets or the source of a connected input)."""
    from aotv_cosim.options import DescribeOptions
    from aotv_cosim.variables import format_table

    _guard(lambda: click.echo(format_table(_execute(DescribeOptions.of(target=target)))))


@main.command("build-fmus")
@click.argument("sources", nargs=-1, metavar="[NAME|SOURCE.py]...")
@click.option("--out", type=UserPath(file_okay=False), help="Put the FMUs here instead of the cache.")
@click.option("--fmi", "fmi_version", type=click.Choice(["2", "3"]),
              help="FMI version of the FMUs: 2 (default) or 3; a pythonfmu3 class is always 3.")
def build_fmus(sources, out, fmi_version):
    """Build the FMUs of fmus_src, or only the given ones: names of this package or your own FMU
    sources (SOURCE.py, any folder; see docs/writing-a-guidance-law.md). Only changed sources are
    rebuilt (content hash)."""
    from aotv_cosim.api import execute
    from aotv_cosim.fmu import build as fmu_build
    from aotv_cosim.fmu.build_progress import BuildProgress
    from aotv_cosim.options import BuildOptions

    def body():
        options = BuildOptions.of(sources=sources, out=out, fmi_version=int(fmi_version) if fmi_version else None)
        refs = [str(s) for s in options.sources] or fmu_build.available_fmus()
        with BuildProgress(total=sum(fmu_build.needs_build(r, options.out, options.fmi_version) for r in refs)) \
                as progress:
            execute(options, progress=progress)

    _guard(body)


@main.command()
@click.argument("scenario", type=UserPath(dir_okay=False))
@click.option("--runs", type=int, required=True, help="Number of runs.")
@click.option("--seed", type=int, default=0, show_default=True, help="Campaign seed.")
@click.option("--out", type=UserPath(), help="Output folder [results/<scenario>-mc].")
@click.option("--resume", is_flag=True, help="Continue an interrupted campaign in --out.")
@click.option("--set", "sets", multiple=True, metavar="COMP.VAR=VALUE", help="Override a value (repeatable).")
@click.option("--keep-series", is_flag=True, help="Keep every run's recorded signals (about 200 rows a run) in "
                                                  "series.parquet and draw the trajectory overlay.")
@_time_options
@_runs_options
def montecarlo(scenario, runs, seed, out, resume, sets, keep_series, start, stop, workers, scheduler, step_timeout,
               max_rss, fmi_calls):
    """Run a Monte Carlo campaign of SCENARIO over its declared dispersions."""
    from aotv_cosim.campaigns.report import console_table
    from aotv_cosim.model.documents import parse_sets
    from aotv_cosim.options import CampaignOptions

    def body():
        out_dir = _default_out(out, scenario, "-mc")
        options = CampaignOptions.of(scenario=scenario, runs=runs, workers=workers, seed=seed, scheduler=scheduler,
                                     out=out_dir, resume=resume,
                                     sets=parse_sets(sets, file=scenario), start=start, stop=stop,
                                     keep_series=keep_series, step_timeout=step_timeout, max_rss=max_rss,
                                     fmi_calls=fmi_calls, progress=True)
        summary = _execute(options).summary
        for warning in summary["warnings"]:
            click.echo(f"warning: {warning}", err=True)
        rate = summary["runs_per_s"]
        click.echo(f"{runs} runs ({summary['runs_this_session']} this session) in {summary['wall_time_s']:.1f} s"
                   + (f", {rate:.1f} runs/s" if rate else "") + f": {summary['statuses']}")
        click.echo(console_table(summary["three_sigma"], summary["units"], summary["outcomes"]))
        click.echo(f"  rows in {out_dir / 'rows.csv'} and rows.parquet, statistics and units in summary.json,"
                   f" tables and plots in {out_dir / 'report.md'}")
        _print_failures(summary, out_dir)
        if summary["status"] == Status.INTERRUPTED:
            click.echo(f"  {summary['stop_reason']}: {summary['runs'] - summary['runs_left']} finished runs kept in "
                       f"{out_dir}; --resume runs the other {summary['runs_left']}")
            sys.exit(_exit_status(summary["status"]))
        if not summary["statuses"].get(Status.COMPLETED):
            failures = summary["failures"] or {"first": {"run": "-", "where": "no run"}, "file": "rows.csv"}
            click.echo(f"error: {scenario}: runs: none of the {runs} runs completed (run {failures['first']['run']}: "
                       f"{failures['first']['where']}); every run's error is in {out_dir / failures['file']}", err=True)
            sys.exit(1)

    _guard(body)


def _print_failures(summary, out_dir):
    """The count of failed runs, the first one's cause and where every failed run's traceback is."""
    failures = summary.get("failures")
    if not failures:
        return
    first = failures["first"]
    click.echo(f"  {failures['count']} run(s) failed; the first, run {first['run']}: {first['where']}", err=True)
    click.echo(f"  every failed run's error and traceback: {out_dir / failures['file']}", err=True)


@main.command()
@click.argument("scenario_set", metavar="SET", type=UserPath())
@click.option("--law", "laws", multiple=True, type=UserPath(dir_okay=False), metavar="FILE",
              help="Your law: a wiring (flown in SET's first scenario) or a scenario with SET's dispersions "
                   "(repeatable).")
@click.option("--runs", type=int, default=1000, show_default=True, help="Runs per law.")
@click.option("--seed", type=int, default=0, show_default=True, help="Campaign seed.")
@click.option("--out", type=UserPath(file_okay=False), help="Output folder [results/<set>-benchmark].")
@click.option("--refly", is_flag=True, help="Fly every law, even those whose stored rows could be reused.")
@_runs_options
def benchmark(scenario_set, laws, runs, seed, out, refly, workers, scheduler, step_timeout, max_rss, fmi_calls):
    """Fly every law (scenario) of SET (a folder, one scenario file, or a shipped set by name:
    benchmark_seed000, benchmark_aerocapture/afe, benchmark_aerocapture/aotv) and each --law through the
    same dispersions; write a scorecard. A law whose scenario, FMUs, dispersions, seed and N are
    unchanged since an earlier benchmark is not flown again: its stored rows are reused."""
    from aotv_cosim.campaigns.benchmark_report import console as scorecard_text
    from aotv_cosim.options import BenchmarkOptions

    def body():
        options = BenchmarkOptions.of(scenario_set=scenario_set, laws=laws, runs=runs, workers=workers, seed=seed,
                                      scheduler=scheduler, out=_default_out(out, scenario_set, "-benchmark"),
                                      reuse=not refly, step_timeout=step_timeout, max_rss=max_rss, fmi_calls=fmi_calls,
                                      progress=True)
        bench = _execute(options, echo=click.echo)
        result, out_dir = bench.result, options.out
        if result["status"] == Status.INTERRUPTED:
            law = result["interrupted_law"]
            done = [name for name in result["laws"] if name != law]
            click.echo(f"  interrupted by {interrupts.name() or 'a signal'} while flying {law}: its finished runs are "
                       f"in {out_dir / law}; laws done before (stored for reuse when flown to the end): "
                       f"{', '.join(done) or 'none'}; no scorecard written", err=True)
            sys.exit(_exit_status(Status.INTERRUPTED))
        click.echo(scorecard_text(result["scorecard"], result["units"]))
        flown = [law for law, info in result["laws"].items() if not info["reused"]]
        click.echo(f"{len(result['scorecard'])} laws x {runs} runs ({len(flown)} flown now in "
                   f"{result['wall_time_s']:.1f} s, {len(result['scorecard']) - len(flown)} reused); scorecard.csv,"
                   f" rows.csv, rows.parquet, report.md and plots in {out_dir}")
        for law in result["failed_laws"]:
            first = result["laws"][law]["first_failure"]
            cause = first.get("where") or " ".join(str(first["error"]).split())
            click.echo(f"error: {law}: runs: every one of its {runs} runs failed (run {first['run']}: {cause}); its "
                       f"rows are not stored for reuse, every run's traceback is in "
                       f"{out_dir / law / 'failures.jsonl'}", err=True)
        if result["failed_laws"]:
            sys.exit(1)

    _guard(body)


@main.command()
@click.argument("scenario", type=UserPath(dir_okay=False))
@click.option("--grid", "grids", multiple=True, required=True, metavar="COMP.VAR=LOW:HIGH:N",
              help="Values of a parameter: N evenly spaced from LOW to HIGH, or A,B,C (SI; repeatable: every "
                   "combination is flown).")
@click.option("--set", "sets", multiple=True, metavar="COMP.VAR=VALUE", help="Override a value (repeatable).")
@click.option("--out", type=UserPath(file_okay=False), help="Output folder [results/<scenario>-sweep].")
@_runs_options
def sweep(scenario, grids, sets, out, workers, scheduler, step_timeout, max_rss, fmi_calls):
    """Fly SCENARIO at every point of the grids: sweep.csv/.parquet (one row per point: the parameters,
    outcome, exit state and extrema, units in the header), sweep.json and sweep.png."""
    from aotv_cosim.model.documents import parse_sets
    from aotv_cosim.options import SweepOptions
    from aotv_cosim.output.display_units import display

    def body():
        options = SweepOptions.of(scenario=scenario, grids=grids, sets=parse_sets(sets, file=scenario),
                                  out=_default_out(out, scenario, "-sweep"), workers=workers, scheduler=scheduler,
                                  step_timeout=step_timeout, max_rss=max_rss, fmi_calls=fmi_calls, progress=True)
        frame = _execute(options)
        result, units = frame.attrs["sweep"], frame.attrs["units"]
        shown = result["parameters"] + [c for c in ("outcome", "outcome.apogee_error", "outcome.dv_total")
                                        if c in units]
        click.echo("  ".join(f"{c} [{display(c, units[c])[0]}]" if units[c] else c for c in shown))
        for row in frame.to_dict("records"):
            cells = [row[c] if isinstance(row[c], str) else f"{float(row[c]) * display(c, units[c])[1]:.6g}"
                     for c in shown]
            click.echo("  ".join(cells))
        click.echo(f"{result['runs']} runs in {result['wall_time_s']:.1f} s; sweep.csv, sweep.parquet (SI) and "
                   f"sweep.png in {options.out}")
        if result["status"] == Status.INTERRUPTED:
            click.echo(f"  interrupted after {result['runs']} of {result['points']} points: those are kept")
            sys.exit(_exit_status(result["status"]))

    _guard(body)


@main.command()
@click.argument("scenario", type=UserPath(dir_okay=False))
@click.option("--lift-to-drag", type=float, metavar="L/D",
              help="L/D flown at full lift up and down by a vehicle steered by its lift acceleration (required "
                   "there); a bank-angle vehicle flies its own C_L/C_D.")
@click.option("--aim", type=click.Choice(["target", "band"]), default="target", show_default=True,
              help="Bounds exit on the target apogee, or on the capture band's edges.")
@click.option("--angle-tolerance", type=float, default=1e-6, show_default=True,
              help="A bisection ends when its gamma0 bracket is this narrow (rad).")
@click.option("--tolerance", type=float, help="A bisection also ends when a run lands this close to the aim (m).")
@click.option("--step", type=float, help="Communication step of the passes (s) [the scenario's, at most 0.1].")
@click.option("--bracket", type=(float, float), default=None, metavar="STEEP SHALLOW",
              help="Entry flight-path angles searched (rad) [outward from the scenario's entry].")
@click.option("--set", "sets", multiple=True, metavar="COMP.VAR=VALUE",
              help="Override a value of the passes flown (repeatable).")
@click.option("--out", type=UserPath(file_okay=False), help="Output folder [results/<scenario>-corridor].")
@_runs_options
def corridor(scenario, lift_to_drag, aim, angle_tolerance, tolerance, step, bracket, sets, out, workers, scheduler,
             step_timeout, max_rss, fmi_calls):
    """The theoretical entry corridor of SCENARIO: the entry flight-path angles bounding capture at
    full lift up (steep bound) and full lift down (shallow bound), by bisection; the plant (bank
    angle or lift acceleration) is read from the wiring; corridor.json, corridor.png. With
    --workers 2 both bounds are searched side by side."""
    import math

    from aotv_cosim.model.documents import parse_sets
    from aotv_cosim.options import CorridorOptions

    def body():
        options = CorridorOptions.of(scenario=scenario, lift_to_drag=lift_to_drag, aim=aim,
                                     angle_tolerance=angle_tolerance, tolerance=tolerance, step=step, bracket=bracket,
                                     sets=parse_sets(sets, file=scenario), out=_default_out(out, scenario, "-corridor"),
                                     workers=workers, scheduler=scheduler,
                                     step_timeout=step_timeout, max_rss=max_rss, fmi_calls=fmi_calls)
        try:
            r = _execute(options)
        except interrupts.Interrupted:
            click.echo(f"  interrupted by {interrupts.name()}: no corridor.json written (the two scenarios flown are "
                       f"in {options.out})", err=True)
            sys.exit(_exit_status(Status.INTERRUPTED))
        flown = f"L/D {r['lift_to_drag']:.4g}" if r["lift_to_drag"] is not None else "its own lift"
        click.echo(f"{'bank-angle' if r['plant'] == 'bank' else 'lift-acceleration'} vehicle ({r['control']}), "
                   f"{flown}; {', '.join(r['removed'])} taken out; {r['step_s']:g} s steps")
        if r["undispersed"]:
            click.echo("dispersed in the scenario, flown at: " + ", ".join(f"{k} = {v:g}"
                                                                          for k, v in r["undispersed"].items()))
        for bound, how in (("steep", "full lift up"), ("shallow", "full lift down")):
            b = r[bound]
            click.echo(f"{bound} bound ({how}): gamma0 = {b['gamma0']:.7g} rad ({math.degrees(b['gamma0']):.5f} deg), "
                       f"apogee error {b['apogee_error'] / 1e3:+.4f} km "
                       f"(aim {b['edge'] / 1e3:+g} km, {b['runs']} runs)")
            low, high = (float(e) for e in b["bracket_errors"] or (b["apogee_error"],) * 2)
            if min(abs(low - b["edge"]), abs(high - b["edge"])) > r["band_m"]:
                click.echo(f"  a sharp edge: the apogee error goes from {low / 1e3:+.6g} to {high / 1e3:+.6g} km "
                           f"between {math.degrees(b['bracket'][0]):.6f} and {math.degrees(b['bracket'][1]):.6f} deg")
        click.echo(f"corridor width {r['width_rad']:.6g} rad ({r['width_deg']:.4f} deg); nominal gamma0 "
                   f"{r['nominal_gamma0']:g} rad; corridor.json and corridor.png in {options.out}")

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
    from aotv_cosim.options import ExportOptions
    from aotv_cosim.ssp.export import default_experiment

    def body():
        system = []
        path = _execute(ExportOptions.of(scenario=scenario, out=out, sets=parse_sets(sets, file=scenario), step=step,
                                         fmi_version=int(fmi_version)),
                        loaded=lambda s: system.append(s.system))
        start, stop, every = default_experiment(path)  # the stop the system reaches (ssp.experiment)
        click.echo(f"{path}: {len(system[0].components)} components, {len(system[0].connections)} connections, "
                   f"{start:g}..{stop:g} s by {every:g} s")

    _guard(body)


@main.command()
@click.argument("comparison", default="scenarios/aotv_compare.json", type=UserPath(dir_okay=False))
@click.option("--out", type=UserPath(file_okay=False), help="Output folder [results/<comparison>].")
@click.option("--no-plots", is_flag=True, help="Skip the overlaid plots.")
def compare(comparison, out, no_plots):
    """Fly every guidance law of COMPARISON [scenarios/aotv_compare.json] through the same
    (dispersed) atmosphere; write comparison.csv and comparison.png, print the table."""
    from aotv_cosim.options import CompareOptions
    from aotv_cosim.studies.compare import format_table

    def body():
        out_dir = _default_out(out, comparison)
        options = CompareOptions.of(comparison=comparison, out=out_dir, plots=not no_plots)
        table = _execute(options, progress=lambda law: click.echo(f"flying {law}", err=True))
        click.echo(format_table(table))
        click.echo(f"table in {out_dir / 'comparison.csv'}")

    _guard(body)


def _with_builds(load, out=None):
    """load(), showing a message and a bar if it builds FMUs (the first use of changed sources);
    with `out`, the folder it writes claimed first (`output.outdir.claimed`: a file or device in
    the way is one line, what it writes is recorded)."""
    import contextlib

    from aotv_cosim.fmu.build_progress import BuildProgress
    from aotv_cosim.output.outdir import claimed

    with claimed(out, ()) if out is not None else contextlib.nullcontext(), BuildProgress():
        return load()


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
                                                     progress=lambda name: click.echo(f"flying {name}", err=True)),
                                    out=out)
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
    def body():
        for name in _with_builds(lambda: make_all(Path(out), guided), out=out):
            click.echo(Path(out) / name)

    _guard(body)


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
        for path in _with_builds(lambda: plot(folder, target), out=target or folder):
            click.echo(path)

    _guard(body)


@figures.command("seed003")
@click.option("--out", type=UserPath(file_okay=False), default="results/seed003_report", show_default=True)
def figures_seed003(out):
    """Seed-003 nominal glide, alpha per elevator law and the saturation study; prints the metrics table
    (runs the scenarios/shuttle_*.json systems, about a minute)."""
    from aotv_cosim.studies.shuttle_report import main as report

    _guard(lambda: _with_builds(lambda: report(out), out=out))
