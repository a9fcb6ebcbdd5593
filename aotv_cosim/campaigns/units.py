"""The unit of every campaign column (rows.csv, rows.parquet, summary.json statistics), and the
display units plots and console tables show them in."""

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


DISPLAY = {"m": ("km", 1e-3), "W/m2": ("W/cm2", 1e-4), "J/m2": ("kJ/cm2", 1e-7)}
"""Display unit and factor (display value = SI value * factor) of the SI units engineers read
otherwise: altitudes and apogees in km, heat rates in W/cm2, heat loads in kJ/cm2. Speeds of the
vehicle (columns ending in .v) are shown in km/s; correction dv stays in m/s; the load factor is
already in g. Files keep SI."""


def display(name, unit) -> tuple:
    """(display unit, factor) of a column in `unit` (SI): `DISPLAY`, km/s for a speed."""
    if unit == "m/s" and name.endswith(".v"):
        return "km/s", 1e-3
    if unit == "1" and "load_factor" in name and not name.startswith("over_"):  # over_*: a count of runs
        return "g", 1.0
    return DISPLAY.get(unit, (unit, 1.0))
