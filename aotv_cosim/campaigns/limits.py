"""Limits that matter in a benchmark: the peaks a vehicle must survive and its control margins.

A scenario states its limits in `"montecarlo": {"outcome": {"limits": {...}}}`: peak load factor
(1, in g0), peak stagnation heat rate (W/m^2; the total, convective plus radiative, of the
vehicle's recorded qdot_total) and peak dynamic pressure (Pa). The outcome classes
do not change; the scorecard gains, for the runs that completed: the percentiles of the peak
dynamic pressure (the vehicle's recorded qbar), of the bank saturation time (`outcome.saturation_time`,
the time the bank command sat on full lift up or down) and of the number of bank reversals (a
recorded `*.reversals` signal, at the exit), and the number of runs above each stated limit and
above any of them. A set without limits keeps its scorecard as it was.
"""

import math

import numpy as np

from aotv_cosim.errors import InputError
from aotv_cosim.status import Status

LIMITED = (("load_factor", "outcome.peak_load_factor", "1"),
           ("heat_rate", "outcome.peak_heat_rate_total", "W/m2"),
           ("dynamic_pressure", "max.{vehicle}.qbar", "Pa"))
"""(limit name, row column of the peak, unit)."""


def of_set(loaded) -> dict:
    """The limits of a set's scenarios, [(path, loaded Scenario)] ({} when none states any);
    InputError when two differ."""
    found: dict = {}
    first = None
    for path, scenario in loaded:
        limits = scenario.outcome.limits.stated() if scenario.outcome is not None else {}
        if first is None:
            first, found = path, limits
        elif limits != found:
            raise InputError(f"its limits differ from those of {first.name}", file=path,
                             entry="montecarlo.outcome.limits", fix="state the same limits in every law of the set")
        total = f"{scenario.outcome.vehicle}.qdot_total" if scenario.outcome is not None else None
        if "heat_rate" in limits and total not in scenario.record:
            raise InputError(f"the heat-rate limit is checked on the total heating, {total}, which it does not "
                             "record", file=path, entry="record", fix=f"add {total} to record")
    return found


def columns(limits: dict) -> list:
    """(column, unit) added to the scorecard; none without limits."""
    if not limits:
        return []
    cols = [("peak_dynamic_pressure_p50", "Pa"), ("peak_dynamic_pressure_p99.865", "Pa"),
            ("saturation_time_p50", "s"), ("saturation_time_p99.865", "s"),
            ("reversals_p50", "1"), ("reversals_max", "1")]
    cols += [(f"over_{name}", "1") for name, _, _ in LIMITED if name in limits]
    return [*cols, ("over_any_limit", "1")]


def _values(rows, column) -> np.ndarray:
    x = np.array([float(r.get(column, math.nan)) for r in rows], dtype=float)
    return x[np.isfinite(x)]


def _reversal_column(rows, at: str) -> str:
    names = [k for k in rows[0] if k.startswith(f"{at}.") and k.endswith(".reversals")] if rows else []
    return names[0] if names else ""


def score(rows, limits: dict, vehicle: str = "vehicle") -> dict:
    """The added scorecard figures of one law's rows (None: not given by the runs)."""
    if not limits:
        return {}
    done = [r for r in rows if r["status"] == Status.COMPLETED]

    def pct(column, p):
        x = _values(done, column)
        return float(np.percentile(x, p)) if len(x) else None

    qbar = f"max.{vehicle}.qbar"
    card = {"peak_dynamic_pressure_p50": pct(qbar, 50.0), "peak_dynamic_pressure_p99.865": pct(qbar, 99.865),
            "saturation_time_p50": pct("outcome.saturation_time", 50.0),
            "saturation_time_p99.865": pct("outcome.saturation_time", 99.865)}
    at_exit, at_end = _reversal_column(done, "exit"), _reversal_column(done, "final")
    flown = [float(r.get(at_exit if math.isfinite(float(r.get("exit.time", math.nan))) else at_end, math.nan))
             for r in done]
    reversals = np.array([x for x in flown if math.isfinite(x)])
    card["reversals_p50"] = float(np.percentile(reversals, 50.0)) if len(reversals) else None
    card["reversals_max"] = float(reversals.max()) if len(reversals) else None
    over_any = np.zeros(len(done), dtype=bool)
    for name, column, _ in LIMITED:
        if name in limits:
            peak = np.array([float(r.get(column.format(vehicle=vehicle), math.nan)) for r in done])
            over = np.nan_to_num(peak, nan=-math.inf) > limits[name]
            card[f"over_{name}"] = int(over.sum())
            over_any |= over
    card["over_any_limit"] = int(over_any.sum())
    return card
