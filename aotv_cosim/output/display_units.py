"""The display units plots and console tables show SI values in, while every file keeps SI.

Engineers read altitudes and apogees in km, angles in deg, heat rates in W/cm2, heat loads in
kJ/cm2, vehicle speeds in km/s and load factors in g; a plot's label or a table's header says the
unit shown. `display(name, unit)` gives (display unit, factor): display value = SI value * factor.
"""

import math

DISPLAY = {"m": ("km", 1e-3), "W/m2": ("W/cm2", 1e-4), "J/m2": ("kJ/cm2", 1e-7),
           "rad": ("deg", 180.0 / math.pi), "rad/s": ("deg/s", 180.0 / math.pi),
           "rad/s2": ("deg/s2", 180.0 / math.pi)}
"""Display unit and factor of the SI units shown otherwise. Speeds of the vehicle (names ending in
.v) are shown in km/s; other m/s (a correction dv) stay; a load factor (unit 1) is in g already."""


def display(name, unit) -> tuple:
    """(display unit, factor) of a signal or column `name` in `unit` (SI): `DISPLAY`, km/s for a
    speed, g for a load factor (not for a count of runs above a limit, over_*)."""
    if unit == "m/s" and name.endswith(".v"):
        return "km/s", 1e-3
    if unit == "1" and "load_factor" in name and not name.startswith("over_"):
        return "g", 1.0
    return DISPLAY.get(unit, (unit, 1.0))
