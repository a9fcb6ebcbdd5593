"""Outcome columns of a campaign row: each run classified by `outcome.classify`.

A scenario asks for them with `"montecarlo": {"outcome": {...}}`, read once into its typed settings
(`model.outcome_settings.OutcomeSettings`: `criteria`, the vehicle and actuator component names),
which every function here takes as `settings`. The row's own final/min/max/exit values are what is
classified (`record_from_row`), so the scenario records the vehicle's h, v and gamma (and heat_load,
qdot_total, heat_load_total for the heat-load and total-heating columns). A run that
reaches the ground is stopped there by the master's range watch on h (status impact) and
classified impact.
"""

import math

from aotv_cosim.mission.outcome import (
    RunOutcome,
    classify,
    record_from_row,
    record_from_summary,
)

CLASS, REASON = "outcome", "outcome.reason"
"""The class column (one of outcome.OUTCOMES) and the text saying why."""

UNITS = {CLASS: "", REASON: "", "outcome.apogee": "m", "outcome.perigee": "m",
         "outcome.apogee_error": "m", "outcome.dv_circ": "m/s", "outcome.dv_total": "m/s",
         "outcome.peak_heat_rate": "W/m2", "outcome.heat_load": "J/m2",
         "outcome.peak_load_factor": "1", "outcome.int_abs_u": "m/s", "outcome.int_u2": "m2/s3",
         "outcome.saturation_time": "s", "outcome.peak_heat_rate_total": "W/m2",
         "outcome.heat_load_total": "J/m2"}
"""Every outcome column and its SI unit (the order is the rows' column order)."""

REQUIRED = ("h", "v", "gamma")
"""The vehicle signals the scenario must record for its runs to be classified."""


def outcome_columns(row: dict, settings) -> dict:
    """{column: value} of UNITS for one finished row (the class and its metrics); `settings`: the
    scenario's `OutcomeSettings`."""
    c = settings.criteria
    record = record_from_row(row, c, settings.vehicle, settings.actuator)
    result: RunOutcome = classify(record, c)
    values = result.as_dict()
    values[CLASS] = values.pop("outcome.outcome")
    return {name: values[name] for name in UNITS}


def run_outcome(summary: dict, settings) -> dict:
    """The outcome of a single run from its summary (`record_from_summary`), as a campaign row
    would give it: {"class", "reason", "apogee", "perigee", "apogee_error", "dv_circ", "dv_total",
    ..., "units": {metric: SI unit}}; a non-finite metric is written "nan" (not provided by the
    run) or "inf" (unbound exit orbit), as summary.json writes every non-finite value.
    `settings`: the scenario's `OutcomeSettings`."""
    c = settings.criteria
    record = record_from_summary(summary, c, settings.vehicle, settings.actuator)
    values = classify(record, c).as_dict(prefix="")
    result = {"class": values.pop("outcome"), "reason": values.pop("reason")}
    result.update({k: v if math.isfinite(v) else str(v) for k, v in values.items()})
    result["units"] = {name.split(".", 1)[1]: unit for name, unit in UNITS.items() if name not in (CLASS, REASON)}
    result["criteria"] = {"target_apogee": c.target_apogee, "band": c.band, "floor": c.floor}
    return result


def counts(rows) -> dict:
    """{class: number of rows} over the rows that have a class, in outcome.OUTCOMES order."""
    from aotv_cosim.mission.outcome import OUTCOMES

    tally = dict.fromkeys(OUTCOMES, 0)
    for r in rows:
        if isinstance(r.get(CLASS), str) and r[CLASS] in tally:
            tally[r[CLASS]] += 1
    return tally

