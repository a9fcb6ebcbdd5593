"""Error-controlled communication steps: what a scenario asks for and how the next step is chosen.

    "step": {"size": 0.5, "tolerance": {"vehicle.h": 1.0}, "min": 0.01, "max": 5.0, "check": "global"}

`size` is the first step (s); `tolerance` gives, per output, the absolute error (in the output's
SI unit) the run may make over its whole span; `min`/`max` bound the step (s); `check` "global"
(default) has the run's global error estimated and the tolerance met on it, "local" only the
local errors (`simulation.step_doubling`). The master then
estimates each step's local coupling error by step doubling (`simulation.step_doubling`) and keeps the sum
of the local errors within the tolerance: a step of length h may make h / (stop - start) of it
(error per unit step). Inputs are extrapolated (`inputs`, local error O(h^3)); held inputs
are refused with a tolerance: their error, first order, is carried on by the states after each
step (a flight-path angle error becomes an altitude error growing with time), so a bound on the
local error of the tolerance signals does not bound the error at the end.
"""

import math
from dataclasses import dataclass

from aotv_cosim.errors import InputError

SAFETY, MOST_SHRINK, MOST_GROWTH = 0.9, 0.2, 4.0
"""Step-size factor: the ideal one times SAFETY, clipped to [MOST_SHRINK, MOST_GROWTH] (the usual
bounds of an embedded Runge-Kutta controller, Hairer-Norsett-Wanner I, Sec. II.4)."""


@dataclass(frozen=True)
class StepControl:
    """tolerance: {signal: absolute error over the run, SI}; smallest and largest step, s;
    check: "global" (the run's global error is estimated and the tolerance met on it,
    `simulation.step_doubling`) or "local" (the local errors alone are kept within it)."""

    tolerance: dict
    min: float
    max: float
    check: str = "global"

    def error_ratio(self, full, halves, h, span):
        """Largest |halves - full| / (tolerance h / span) over the signals: <= 1 accepts the step.

        full, halves: the signals (in `tolerance` order) after one step of h and after two of h/2
        from the same state; their difference estimates the local error of the two halves."""
        return max(abs(b - a) / (tol * h / span)
                   for a, b, tol in zip(full, halves, self.tolerance.values()))

    def next_step(self, h, ratio):
        """The step to try next (s) after a step h whose error ratio was `ratio`: with
        extrapolated inputs the local error per unit step is O(h^2)."""
        factor = MOST_GROWTH if ratio == 0.0 else SAFETY * ratio ** -0.5
        return min(self.max, max(self.min, h * min(MOST_GROWTH, max(MOST_SHRINK, factor))))


def step_control(step: dict, size: float, path) -> "StepControl | None":
    """The StepControl of a scenario's "step" object, or None for a fixed step; InputError
    when a bound is not a positive number or the first step lies outside [min, max]."""
    if "tolerance" not in step:
        for key in ("min", "max", "check"):
            if key in step:
                raise InputError(f"step.{key} without step.tolerance", file=path, entry=f"step.{key}",
                                 fix="add \"tolerance\": {\"component.output\": error} or drop it")
        return None
    if step.get("inputs") == "held":
        raise InputError("error-controlled steps with held inputs: their first-order coupling error "
                         "grows through the states after each step (on the seed-000 pass 1 m asked "
                         "of h gives 71 m), which a local estimate does not see", file=path,
                         entry="step.inputs", fix="drop \"inputs\" (extrapolated is the default "
                         "with a tolerance) or give a fixed step size")
    tolerance = {str(k): float(v) for k, v in step["tolerance"].items()}
    bad = [k for k, v in tolerance.items() if not (math.isfinite(v) and v > 0)]
    if bad or not tolerance:
        raise InputError(f"tolerance of {', '.join(bad) or 'no signal'} is not a positive number",
                         file=path, entry="step.tolerance",
                         fix="give each signal's allowed error over the run in its SI unit, e.g. 1.0")
    low, high = float(step.get("min", size * 1e-3)), float(step.get("max", size * 100.0))
    if not (0 < low <= size <= high and math.isfinite(high)):
        raise InputError(f"need 0 < min <= size <= max, got min {low:g}, size {size:g}, max {high:g} s",
                         file=path, entry="step", fix="give step bounds around the first step size")
    return StepControl(tolerance, low, high, step.get("check", "global"))
