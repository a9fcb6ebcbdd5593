"""The stop time of an exported SSP's default experiment: one the system reaches.

SSP has no stop conditions, so an importer runs the default experiment to its stop time. A
scenario that ends at a stop condition (e.g. seed 002's Mach 2.7 energy, reached at 749 s of a
1000 s scenario) may not survive to its own `stop`: the entry tracking law leaves its reference
table and fails at 811 s. So for such a scenario the export runs it once in this master and
takes the last communication point at or before the located event.
"""

import math
import tempfile
from pathlib import Path

from aotv_cosim.errors import InputError
from aotv_cosim.status import Status


def reachable_stop(scenario) -> float:
    """The scenario's stop (s) without stop conditions; with them, start + n step, the last
    communication point not after the event of a run in this master (InputError if that run
    does not complete)."""
    if not scenario.stop_conditions:
        return scenario.stop
    from aotv_cosim.output.runner import run_scenario

    with tempfile.TemporaryDirectory(prefix="aotv_export_") as tmp:
        summary = run_scenario(scenario, Path(tmp), make_plots=False)
    if summary.status != Status.COMPLETED:
        raise InputError(f"the scenario's run ends {summary.status} ({summary.error}), so no stop "
                         "time it reaches can be exported", file=scenario.path, entry="stop",
                         fix="export a scenario whose run completes, or remove its stop conditions")
    event = summary.event
    if event is None:
        return scenario.stop
    n = math.floor((event["time"] - scenario.start) / scenario.step + 1e-9)
    return scenario.start + n * scenario.step
