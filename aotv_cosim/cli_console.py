"""What the command line prints about a run: its progress bar and its summary table (every
recorded signal with its unit, final value and extrema), failures, warnings and expectations.
"""

import sys
from pathlib import Path

import click

from aotv_cosim.status import Status


def progress_bar(scenario):
    from tqdm import tqdm

    bar = tqdm(total=round(scenario.stop - scenario.start, 6), unit="s sim", delay=2.0,
               file=sys.stderr, leave=False, bar_format="{l_bar}{bar}| {n:.0f}/{total:.0f} s [{elapsed}<{remaining}]")

    def update(t):
        bar.n = round(t - scenario.start, 6)
        bar.refresh() if bar.n >= bar.total else bar.update(0)

    return bar, update


def finish_bar(bar, summary, start):
    """Put the bar at 100 % of the simulated span when a stop condition ended the run, and keep a
    bar that says why a run stopped early (stop condition, failure, interruption) when it is
    closed. A bar never shown (a run shorter than its delay) stays hidden. `summary`: the run's
    `output.summary.RunSummary`."""
    if Status(summary.status).ended_cleanly and summary.end_time is not None:
        bar.total = bar.n = round(summary.end_time - start, 6)
    if summary.stop_reason != "stop time reached":
        bar.set_postfix_str(summary.stop_reason, refresh=False)
        bar.leave = True


def print_summary(summary, out_dir):
    """The run's status, its signals' final values and extrema and its expectations
    (`summary`: its `output.summary.RunSummary`)."""
    click.echo(f"{Path(summary.scenario).name}: {summary.status} ({summary.stop_reason}), "
               f"{summary.steps} steps in {summary.wall_time_s:.3f} s")
    print_failure(summary)
    if summary.event:
        click.echo(f"  event at t = {summary.event['time']:.6g} s")
    names = list(summary.final)
    if names:
        units = summary.units
        width = max(len(n) for n in names)
        uwidth = max([len("unit")] + [len(units.get(n, "")) for n in names])
        click.echo(f"  {'signal':<{width}}  {'unit':<{uwidth}}  {'final':>14}  {'min':>14}  {'max':>14}")
        for n in names:
            none = None if (summary.types or {}).get(n) == "String" else float("nan")  # no extrema
            lo = _cell(summary.min.get(n, {}).get("value", none))
            hi = _cell(summary.max.get(n, {}).get("value", none))
            click.echo(f"  {n:<{width}}  {units.get(n, ''):<{uwidth}}  {_cell(summary.final[n])}  {lo}  {hi}")
    print_expectations(summary.expectations)
    click.echo(f"  results in {out_dir}")


def _cell(value) -> str:
    """A summary value in a 14-character column: a Real with 7 significant digits, an Integer
    exactly, a Boolean as true/false, a text as it is."""
    if isinstance(value, bool):
        return f"{str(value).lower():>14}"
    if isinstance(value, float):
        return f"{value:14.7g}"
    if isinstance(value, int):
        return f"{value:>14d}"
    return f"{value:>14}" if value is not None else f"{'':>14}"


def _shown(value) -> str:
    """An expectation's value on the console: numbers with 7 significant digits."""
    if isinstance(value, bool):
        return str(value).lower()
    return f"{value:.7g}" if isinstance(value, (int, float)) else repr(value)


def print_failure(summary):
    """The failure line, the failing FMU's last log message, and any warnings (on stderr) of a
    run's `output.summary.RunSummary`."""
    if summary.error:
        click.echo(f"  failure: {summary.error}")
        log = (summary.error_detail or {}).get("fmu_log") or []
        if log and log[-1].split(": ", 1)[-1] not in summary.error:
            click.echo(f"  FMU log: {log[-1]}")
    if summary.status == Status.INTERRUPTED:
        click.echo(f"  interrupted at t = {summary.end_time} s; partial results kept")
    request = summary.terminate_request
    if request:
        click.echo(f"  {request['component']} asked to end the simulation (fmi2Terminated); rows up to "
                   f"t = {summary.end_time} s kept")
    for warning in summary.warnings:
        click.echo(f"warning: {warning}", err=True)


def print_expectations(results):
    for r in results:
        measured = "not measured" if r["measured"] is None else _shown(r["measured"])
        within = f" +- {r['allowed_error']:.3g}" if r["allowed_error"] is not None else ""
        click.echo(f"  [{'PASS' if r['passed'] else 'FAIL'}] {r['signal']} at {r['at']}: "
                   f"{measured} vs {_shown(r['expected'])}{within}  ({r['source']})")
