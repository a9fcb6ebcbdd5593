"""How big a scenario's run is: rows it will write, and whether its time values can carry its step.

Called when a scenario is loaded (so by `validate` and at the start of `run`, `check` and a
Monte Carlo campaign):

- `ROWS_WARNING`: a run that will write more rows than this gets a warning on stderr (stop
  1e6 s at 0.001 s asks for 1e9 rows, tens of GB of CSV), naming the fix (a larger step or
  `record_every`).
- a step below the resolution of the time values is refused: communication points are
  start + k step in binary64, spaced by multiples of ulp(t) (16 s near t = 1e17 s), so a step
  of 1 s there gives repeated and uneven times. Refused when ulp(max(|start|, |stop|)) exceeds
  `RESOLUTION_FRACTION` of the step.
"""

import math
import sys

from aotv_cosim.errors import InputError

ROWS_WARNING = 5_000_000
"""Rows of timeseries.csv above which loading a scenario warns (about 1 GB with 12 signals)."""
RESOLUTION_FRACTION = 1e-3
"""Largest spacing of the time values near the run, as a fraction of the step, that is accepted."""


def rows_to_write(scenario) -> int:
    """Rows of timeseries.csv the run writes if it reaches its stop: start, then every
    record_every-th communication point and the last one."""
    steps = max(1, math.ceil((scenario.stop - scenario.start) / scenario.step - 1e-9))
    return 1 + math.ceil(steps / scenario.record_every)


def check_run_size(scenario) -> list:
    """Problems with the scenario's times (InputErrors); warns on stderr about a large run."""
    resolution = math.ulp(max(abs(scenario.start), abs(scenario.stop)))
    if resolution > RESOLUTION_FRACTION * scenario.step:
        return [InputError(f"step {scenario.step:g} s is below the resolution of the time values: near "
                           f"t = {max(abs(scenario.start), abs(scenario.stop)):g} s consecutive times "
                           f"differ by multiples of {resolution:g} s", file=scenario.path, entry="step",
                           fix=f"give a step of at least {resolution / RESOLUTION_FRACTION:g} s, or start "
                               "the run nearer t = 0")]
    rows = rows_to_write(scenario)
    if rows > ROWS_WARNING:
        print(f"warning: {scenario.path}: the run will write {rows:.3g} rows of timeseries.csv (more than "
              f"{ROWS_WARNING:.0e}); give a larger step or record_every to write fewer", file=sys.stderr)
    return []
