"""Physical ranges the FMUs declare (FMI 2.0 `min`/`max` of a variable, SI, inclusive).

The FMUs of ``fmus_src`` declare them (`fmu_slave.AotvSlave`): altitudes and masses that cannot be
negative, angles within +-90 deg, the allowed codes of integer switches. Two uses:

- `check_range`: a value given to a parameter or an unconnected input (wiring `parameters`,
  scenario `parameters`, `--set`, and so Monte Carlo draws, which are scenario overrides) outside
  the declared range is refused when the system is loaded (exit 2).
- `range_watches`: while a run goes, an output leaving its declared range stops it like a stop
  condition, at the interpolated crossing, with the results kept; the vehicles' altitude `h`
  (declared min 0) so stops a run that reaches the ground with status `impact`.
"""

import math
from dataclasses import dataclass

from aotv_cosim.errors import InputError
from aotv_cosim.status import Status


def declared_range(fmu, name):
    """(low, high) declared for variable `name` of the FmuInfo `fmu` (+-inf where not declared),
    or None when it declares neither."""
    var = next((v for v in fmu.model_description.modelVariables if v.name == name), None)
    if var is None or (var.min is None and var.max is None):
        return None
    return (-math.inf if var.min is None else float(var.min), math.inf if var.max is None else float(var.max))


def _interval(low, high):
    return f"[{low:g}, {high:g}]"


def check_range(fmu, name, value, *, file, entry):
    """Problems with giving `value` to variable `name` of `fmu`: outside its declared range."""
    bounds = declared_range(fmu, name)
    if bounds is None or isinstance(value, (str, bool)) or bounds[0] <= value <= bounds[1]:
        return []
    unit = fmu.variables[name].unit
    return [InputError(f"{name} = {value!r} is outside its physical range {_interval(*bounds)}"
                       + (f" {unit}" if unit and unit != "1" else ""), file=file, entry=entry,
                       fix=f"give a value in {_interval(*bounds)} (declared by the {fmu.model_identifier} FMU; "
                           "values are SI: m, m/s, rad)")]


@dataclass(frozen=True)
class RangeWatch:
    """A stop on an output leaving its declared range: the `crosses`/`direction` of a stop
    condition on `signal`, and the run's status and message when it fires."""

    signal: str
    threshold: float
    direction: str
    status: Status
    message: str


def range_watches(system, read):
    """The RangeWatches of every output in `read` ('comp.var' signals the master reads) that
    declares a min or max. An altitude `h` below its min is an `impact`; any other output
    leaving its range is `out_of_range`."""
    watches = []
    for signal in read:
        comp, var = signal.split(".", 1)
        bounds = declared_range(system.components[comp].fmu, var)
        if bounds is None:
            continue
        low, high = bounds
        if math.isfinite(low):
            impact = var == "h"
            watches.append(RangeWatch(signal, low, "down", Status.IMPACT if impact else Status.OUT_OF_RANGE,
                                      f"{signal} reached the ground (h = {low:g} m)" if impact
                                      else f"{signal} fell below its declared min {low:g}"))
        if math.isfinite(high):
            watches.append(RangeWatch(signal, high, "up", Status.OUT_OF_RANGE,
                                      f"{signal} rose above its declared max {high:g}"))
    return watches


def check_dispersion(fmu, name, dispersion, *, file, entry):
    """Problems with a Monte Carlo dispersion of variable `name` of `fmu`: its bounds (uniform,
    truncated_normal) or, for a normal, its mean outside the declared range, so that the draws
    would give the FMU values it does not accept."""
    bounds = declared_range(fmu, name)
    if bounds is None:
        return []
    given = {"low": dispersion.low, "high": dispersion.high} if dispersion.low is not None \
        else {"mean": dispersion.mean}
    bad = {k: v for k, v in given.items() if v is not None and not bounds[0] <= v <= bounds[1]}
    if not bad:
        return []
    return [InputError(f"{', '.join(f'{k} = {v!r}' for k, v in bad.items())} of {dispersion.signal} lies outside "
                       f"its physical range {_interval(*bounds)}", file=file, entry=entry,
                       fix=f"keep the dispersion within {_interval(*bounds)} (declared by the "
                           f"{fmu.model_identifier} FMU; values are SI)")]
