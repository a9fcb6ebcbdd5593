"""What a finished campaign reports beside its rows: the 3-sigma statistics table and outcome
counts (summary.json, report.md, console) and the plots (`figures`)."""

from aotv_cosim.campaigns import figures, report_tables
from aotv_cosim.errors import InputError


def chosen(scenario, names) -> tuple:
    """(columns, versus) of the report: `montecarlo.columns` and `montecarlo.versus` of the
    scenario, else the defaults (`report_tables.default_columns`; every dispersed input against
    the first non-input column). Raises InputError for a name that is not a row column."""
    columns = scenario.report_columns or report_tables.default_columns(scenario)
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
    table = report_tables.three_sigma(rows, columns)
    outcomes = report_tables.outcome_counts(rows, scenario)
    plots, notes = figures.plots(out, rows, scenario, units, columns, versus) if make_plots else ([], [])
    title = f"Campaign: {scenario.path.name}, {len(rows)} runs"
    (out / "report.md").write_text(report_tables.markdown(title, table, units, outcomes, plots, notes))
    return {"three_sigma": table, "outcomes": outcomes, "plots": plots, "report_notes": notes}
