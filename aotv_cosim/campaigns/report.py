"""A finished campaign's report beside its rows: the 3-sigma statistics table with units, the
outcome counts, the console text and report.md, and the plots (`figures`).

The 3-sigma-equivalent band of a column is its 0.135 and 99.865 percentiles (the probability
outside +-3 sigma of a normal law, 0.27 %, split between the tails), read from the sample, not
from mean +- 3 std, so a skewed or bounded column keeps its own tails. With fewer than about
740 runs (1 / 0.00135) those percentiles are interpolated between the two extreme runs.
"""

import math

from aotv_cosim.campaigns import figures
from aotv_cosim.campaigns.statistics import completed_values, sample_statistics
from aotv_cosim.errors import InputError
from aotv_cosim.mission.outcome_rows import CLASS, counts

BAND = (0.135, 50.0, 99.865)
"""Percentiles of the tables: the 3-sigma-equivalent band and the median."""

FIELDS = ("n", "mean", "std", "p0.135", "p50", "p99.865", "min", "max")


def default_columns(scenario) -> list:
    """The report's columns when the scenario names none (`montecarlo.columns`): the dispersed
    inputs, the outcome metrics if runs are classified, else the exit (or final) values."""
    names = [f"dispersed.{d.signal}" for d in scenario.dispersions]
    if scenario.outcome is not None:
        return [*names, "outcome.apogee_error", "outcome.dv_total", "outcome.peak_heat_rate",
                "outcome.peak_load_factor", "outcome.int_abs_u"]
    at = "exit" if scenario.stop_conditions else "final"
    return names + [f"{at}.{s}" for s in scenario.record]


def three_sigma(rows, columns) -> dict:
    """{column: {n, mean, std, p0.135, p50, p99.865, min, max}} over the completed runs (a
    column without a finite value is left out)."""
    table = {}
    for name in columns:
        x = completed_values(rows, name)
        if len(x):
            stats = sample_statistics(x, BAND)
            table[name] = {field: stats[field] for field in FIELDS}
    return table


def _number(v) -> str:
    if isinstance(v, int):
        return str(v)
    return "nan" if not math.isfinite(v) else f"{v:.6g}"


def console_table(table: dict, units: dict, outcomes: dict | None = None) -> str:
    """Plain-text statistics table (one line per column, unit beside the name) and the
    outcome counts, as printed after a campaign: in display units (km, km/s, W/cm2, kJ/cm2, g;
    `units.display`), while summary.json and report.md keep SI."""
    from aotv_cosim.output.display_units import display

    heads = ("column", "unit", *FIELDS)
    lines = []
    for name, stats in table.items():
        shown, factor = display(name, units.get(name, ""))
        lines.append([name, shown or "-"] + [_number(stats[f] if f == "n" else stats[f] * factor) for f in FIELDS])
    widths = [max(len(str(c)) for c in col) for col in zip(heads, *lines)]
    text = ["  ".join(h.ljust(w) if k < 2 else h.rjust(w) for k, (h, w) in enumerate(zip(heads, widths)))]
    text += ["  ".join(c.ljust(w) if k < 2 else c.rjust(w) for k, (c, w) in enumerate(zip(line, widths)))
             for line in lines]
    if outcomes:
        total = sum(outcomes.values())
        text.append("outcomes: " + ", ".join(f"{k} {n} ({100.0 * n / total:.1f} %)"
                                             for k, n in outcomes.items()) if total else "outcomes: none")
    return "\n".join(text)


def markdown(title: str, table: dict, units: dict, outcomes: dict, plots, notes=()) -> str:
    """report.md: the statistics table, the outcome counts, notes and the plots."""
    out = [f"# {title}", "", "| column | unit | " + " | ".join(FIELDS) + " |",
           "|---|---|" + "---:|" * len(FIELDS)]
    out += [f"| `{name}` | {units.get(name, '') or '-'} | " + " | ".join(_number(s[f]) for f in FIELDS) + " |"
            for name, s in table.items()]
    out += ["", "p0.135 and p99.865 bound the 3-sigma-equivalent band (sample percentiles of the "
                "completed runs)."]
    if outcomes:
        out += ["", "| outcome | runs |", "|---|---:|"] + [f"| {k} | {n} |" for k, n in outcomes.items()]
    out += [""] + [f"- {n}" for n in notes] + ([""] if notes else [])
    out += [f"![{p}]({p})" for p in plots]
    return "\n".join(out) + "\n"


def outcome_counts(rows, scenario):
    """Outcome counts when the scenario classifies its runs, else None."""
    return counts(rows) if scenario.outcome is not None and rows and CLASS in rows[0] else None


def chosen(scenario, names) -> tuple:
    """(columns, versus) of the report: `montecarlo.columns` and `montecarlo.versus` of the
    scenario, else the defaults (`default_columns`; every dispersed input against
    the first non-input column). Raises InputError for a name that is not a row column."""
    columns = scenario.report_columns or default_columns(scenario)
    inputs = [n for n in columns if n.startswith("dispersed.")]
    outputs = [n for n in columns if not n.startswith("dispersed.")]
    versus = scenario.versus or ([(x, outputs[0]) for x in inputs] if outputs else [])
    known = set(names)
    for entry, listed in (("montecarlo.columns", columns), ("montecarlo.versus", [n for p in versus for n in p])):
        for name in listed:
            if name not in known:
                numeric = [n for n in names if n not in ("run", "status", "error", "outcome", "outcome.reason")]
                raise InputError(f"{name!r} is not a campaign column", file=scenario.path, entry=entry,
                                 fix="give one of " + ", ".join(numeric))
    return list(columns), [tuple(p) for p in versus]


def write(out, rows, scenario, units, names, make_plots=True) -> dict:
    """Write report.md (and the plots) in `out`; returns the summary entries three_sigma,
    outcomes, plots and report_notes."""
    columns, versus = chosen(scenario, names)
    table = three_sigma(rows, columns)
    outcomes = outcome_counts(rows, scenario)
    plots, notes = figures.plots(out, rows, scenario, units, columns, versus) if make_plots else ([], [])
    title = f"Campaign: {scenario.path.name}, {len(rows)} runs"
    (out / "report.md").write_text(markdown(title, table, units, outcomes, plots, notes))
    return {"three_sigma": table, "outcomes": outcomes, "plots": plots, "report_notes": notes}
