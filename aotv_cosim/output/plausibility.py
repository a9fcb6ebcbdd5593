"""Plausibility warnings: values given in the wrong unit, and runs whose physics degenerated.

A value outside an FMU's declared `min`/`max` is refused (`model.ranges`); these are values that
lie in range but are implausible, so the run goes on and its summary says why it may be wrong:

- a parameter (or an unconnected input) given more than `FACTOR` times above or below the FMI
  `nominal` its FMU declares (the typical magnitude of the quantity in its SI unit; a user's law
  declares it with `nominal=` in `aotv_cosim.laws`): `atmosphere.scale_height = 7.045 m is
  1000x below its nominal 7045 m; km given for m?`. 30 catches a km typed for m (1000x) and
  degrees typed for radians (57.3x) and lets through the spread of real cases (entry speeds of
  1.8-8.2 km/s against a nominal 8.2 km/s);
- a run whose recorded dynamic pressure (an output in Pa) stayed below `QBAR_FLOOR` throughout:
  no aerodynamic force acted, e.g. a scale height in km gives an airless atmosphere;
- a run whose recorded air density (an output in kg/m3) stayed below `RHO_FLOOR` throughout: the
  vehicle never entered the atmosphere (that density is met about 150 km up on Earth).
"""

import math

FACTOR = 30.0
"""A given value more than this many times above or below its nominal is warned about."""
QBAR_FLOOR = 1.0
"""Pa: a dynamic pressure below this over a whole run means no aerodynamic force (an entry meets
kilopascals; 1 Pa is the dynamic pressure at 8 km/s near 140 km)."""
RHO_FLOOR = 1e-9
"""kg/m3: a density below this over a whole run means the vehicle flew in vacuum."""

_SLIPS = (("rad", 180.0 / math.pi, "degrees given for rad?"),)
"""(unit, ratio above nominal, likely slip) besides the km-for-m family (`_hint`)."""


def _near(ratio: float, target: float) -> bool:
    return abs(math.log10(ratio / target)) < 0.02


def _hint(unit: str, ratio: float) -> str:
    """The likely unit slip behind a value `ratio` times its nominal, or what to check."""
    if unit.startswith("m") and ratio < 1.0:
        power = int(unit[1]) if unit[1:2].isdigit() else 1  # m2, m3/s2: a km is 1000**power of them
        if _near(1.0 / ratio, 1000.0 ** power):
            return f"k{unit} given for {unit}?"
    for slip_unit, slip_ratio, slip in _SLIPS:
        if unit == slip_unit and _near(ratio, slip_ratio):
            return slip
    return f"check the value and its unit ({unit or 'dimensionless'})"


GIVEN = ("parameter", "input")
"""Causalities of the variables a system gives values to (an input: while unconnected)."""


def unit_slips(system) -> list:
    """A warning for every parameter or input value of `system` (wiring, scenario and --set
    values) more than FACTOR from the nominal its FMU declares."""
    warnings = []
    for name, comp in system.components.items():
        declared = {v.name: v for v in comp.fmu.model_description.modelVariables
                    if v.nominal is not None and v.causality in GIVEN}
        for var, value in comp.parameters.items():
            variable = declared.get(var)
            if variable is None or isinstance(value, bool) or not isinstance(value, (int, float)) or value == 0:
                continue
            nominal = float(variable.nominal)
            ratio = abs(value / nominal) if nominal else math.inf
            if nominal and (ratio > FACTOR or ratio < 1.0 / FACTOR):
                unit = variable.unit or (variable.declaredType.unit if variable.declaredType else "") or ""
                times = max(ratio, 1.0 / ratio)
                warnings.append(f"{name}.{var} = {value:.7g} {unit} is {times:.4g}x "
                                f"{'below' if ratio < 1 else 'above'} its nominal {nominal:.7g} {unit}; "
                                f"{_hint(unit, ratio)}".replace("  ", " "))
    return warnings


def degenerate_physics(units: dict, maxima: dict) -> list:
    """Warnings for a run whose dynamic pressure or density stayed negligible throughout, from the
    units ({signal: unit}) and largest values ({signal: {"value": v, ...}}) of its recorded signals."""
    warnings = []
    for signal, unit in units.items():
        peak = (maxima.get(signal) or {}).get("value")
        if peak is None or not math.isfinite(peak):
            continue
        if unit == "Pa" and abs(peak) < QBAR_FLOOR:
            warnings.append(f"{signal} stayed below {QBAR_FLOOR:g} Pa over the whole run (max {peak:.3g} Pa): "
                            "the vehicle met no atmosphere, no aerodynamic force acted; check the atmosphere's "
                            "and the entry state's values and units")
        elif unit == "kg/m3" and abs(peak) < RHO_FLOOR:
            warnings.append(f"{signal} stayed below {RHO_FLOOR:g} kg/m3 over the whole run (max {peak:.3g} "
                            "kg/m3): the vehicle never entered the atmosphere")
    return warnings


def run_warnings(scenario, summary) -> list:
    """The plausibility warnings of a finished run's `summary.RunSummary` (values given, then
    physics seen)."""
    return unit_slips(scenario.system) + degenerate_physics(summary.units, summary.max)
