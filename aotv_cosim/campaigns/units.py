"""The unit of every campaign column (rows.csv, rows.parquet, summary.json statistics); the display
units plots and console tables show them in are `output.display_units`'s."""

from aotv_cosim.mission.outcome_rows import UNITS as OUTCOME_UNITS
from aotv_cosim.output.series import TIME_UNIT

NO_UNIT = {"run": "", "status": "", "error": "", "steps": "1"}
"""Columns that are not physical quantities: an index, texts, a count."""


def column_units(scenario, names) -> dict:
    """{column: unit}: a signal's columns (dispersed., final., min., max., exit.) carry the unit
    its FMU declares; end_time and exit.time are in s."""
    units = {}
    for name in names:
        if name in NO_UNIT:
            units[name] = NO_UNIT[name]
        elif name in OUTCOME_UNITS:
            units[name] = OUTCOME_UNITS[name]
        elif name in ("end_time", "exit.time"):
            units[name] = TIME_UNIT
        else:
            units[name] = scenario.system.variable(name.split(".", 1)[1]).unit
    return units
