"""Outcome of one aeroassisted run: captured, skip_out, undershoot, impact or failed, with metrics.

A pure function of what a run reports (a Monte Carlo row or a run's summary.json). The rules, in this order:

1. impact: the altitude went below zero (min h < 0, or the master stopped the run at the ground);
2. failed: the run did not complete (an FMU or solver failure, or an interruption): its message;
3. undershoot: the altitude went below the floor, or the vehicle never left the atmosphere
   (no climbing crossing of the exit altitude), or the exit apogee is below the band;
4. skip_out: the exit orbit is unbound, or its apogee is above the band;
5. captured: the exit apogee is within target +- band.

Metrics (SI; nan when the run does not provide them): exit-orbit apogee and perigee altitudes
(`physics.orbit.apsis_altitudes`, extraction Sec. 7), apogee error (apogee - target), dv_circ
(the circularisation impulse at the exit orbit's own apogee, Ch. 9), dv_total (the two-impulse
correction into the circular orbit at the target altitude, `physics.orbit_correction`), peak
heat rate (W/m^2), heat load (J/m^2, if the vehicle integrates it), peak load factor, the
control effort integrals of |u| (m/s) and u^2 (m^2/s^3) up to the exit, saturation time (s, if
the actuator reports it), and the peak heat rate and heat load of the total (convective plus
radiative) stagnation heating (the vehicle's qdot_total and heat_load_total; the first two heating
metrics are the convective ones, qdot and heat_load).
"""

import math
from dataclasses import asdict, dataclass

from aotv_cosim.physics import orbit
from aotv_cosim.physics.constants import MU_EARTH, R_EARTH_000
from aotv_cosim.physics.orbit_correction import circularization_corrections
from aotv_cosim.physics.planar import EXIT_000
from aotv_cosim.status import Status

OUTCOMES = ("captured", "skip_out", "undershoot", "impact", "failed")

NAN = math.nan


@dataclass(frozen=True)
class CaptureCriteria:
    """What counts as a capture. target_apogee: target apogee altitude, m (seed 000: the apogee
    of the orbit through the Table 4.1 exit state, 1191.154 km); band: half-width of the accepted
    apogee band, m; floor: an altitude below it before exit is an undershoot, m; exit_altitude:
    the atmospheric interface, m; r_earth m, mu m^3/s^2 of the orbit computations."""

    target_apogee: float
    band: float
    floor: float
    exit_altitude: float = EXIT_000[0]
    r_earth: float = R_EARTH_000
    mu: float = MU_EARTH

    @classmethod
    def seed000(cls, band: float = 10e3, floor: float = 60e3) -> "CaptureCriteria":
        """Seed-000 criteria: the Table 4.1 exit orbit's apogee as target. The band (default
        +-10 km) and floor (default 60 km, under the 78-80 km lowest points of the guided
        passes) are mission choices: the thesis states neither."""
        return cls(orbit.apsis_altitudes(*EXIT_000)[1], band, floor)


@dataclass(frozen=True)
class RunRecord:
    """What one run reports. status: "completed" or otherwise (failed, interrupted, error);
    error: its message; exit: (h m, v m/s, gamma rad) where the vehicle left the atmosphere, or
    None; min_altitude m; the other fields are the metrics of the module docstring, nan when the
    run does not record them (effort integrals at the exit when the run has one)."""

    status: str
    error: str = ""
    exit: tuple[float, float, float] | None = None
    min_altitude: float = NAN
    peak_heat_rate: float = NAN
    heat_load: float = NAN
    peak_load_factor: float = NAN
    int_abs_u: float = NAN
    int_u2: float = NAN
    saturation_time: float = NAN
    peak_heat_rate_total: float = NAN
    heat_load_total: float = NAN


@dataclass(frozen=True)
class RunOutcome:
    """The class of one run (one of OUTCOMES), why, and its metrics (module docstring)."""

    outcome: str
    reason: str
    apogee: float = NAN
    perigee: float = NAN
    apogee_error: float = NAN
    dv_circ: float = NAN
    dv_total: float = NAN
    peak_heat_rate: float = NAN
    heat_load: float = NAN
    peak_load_factor: float = NAN
    int_abs_u: float = NAN
    int_u2: float = NAN
    saturation_time: float = NAN
    peak_heat_rate_total: float = NAN
    heat_load_total: float = NAN

    def as_dict(self, prefix: str = "outcome.") -> dict:
        """{prefix + field: value}, for a row or a summary."""
        return {prefix + k: v for k, v in asdict(self).items()}


def _exit_orbit(exit_state, c: CaptureCriteria):
    """(apogee, perigee, apogee_error, dv_circ, dv_total) of the exit orbit; apogee inf and the
    rest nan when it is unbound."""
    h, v, gamma = exit_state
    r = c.r_earth + h
    if 0.5 * v * v >= c.mu / r:
        return math.inf, NAN, math.inf, NAN, NAN
    perigee, apogee = orbit.apsis_altitudes(h, v, gamma, c.mu, c.r_earth)
    dv_circ = orbit.circularization_delta_v(h, v, gamma, c.mu, c.r_earth)
    dv1, dv2 = circularization_corrections(c.r_earth + perigee, c.r_earth + apogee,
                                           c.r_earth + c.target_apogee, c.mu)
    return apogee, perigee, apogee - c.target_apogee, dv_circ, dv1 + dv2


def classify(run: RunRecord, c: CaptureCriteria) -> RunOutcome:
    """Classify one run by the rules of the module docstring and compute its metrics."""
    metrics = dict(peak_heat_rate=run.peak_heat_rate, heat_load=run.heat_load,
                   peak_load_factor=run.peak_load_factor, int_abs_u=run.int_abs_u,
                   int_u2=run.int_u2, saturation_time=run.saturation_time,
                   peak_heat_rate_total=run.peak_heat_rate_total, heat_load_total=run.heat_load_total)
    if run.exit is not None:
        apogee, perigee, error, dv_circ, dv_total = _exit_orbit(run.exit, c)
        metrics.update(apogee=apogee, perigee=perigee, apogee_error=error, dv_circ=dv_circ,
                       dv_total=dv_total)

    def result(outcome, reason):
        return RunOutcome(outcome, reason, **metrics)

    if run.status == Status.IMPACT or run.min_altitude < 0.0:  # the master stops a run at the ground
        return result("impact", f"altitude below zero (min h = {run.min_altitude:.6g} m)")
    if run.status != Status.COMPLETED:
        return result("failed", run.error or f"run {run.status}")
    if run.min_altitude < c.floor:
        return result("undershoot", f"altitude {run.min_altitude:.6g} m below the floor {c.floor:.6g} m")
    if run.exit is None:
        return result("undershoot", f"never climbed back through {c.exit_altitude:.6g} m")
    error = metrics["apogee_error"]
    if math.isinf(metrics["apogee"]):
        return result("skip_out", "exit orbit unbound")
    if error > c.band:
        return result("skip_out", f"apogee {error:+.6g} m off the target, above the band +-{c.band:.6g} m")
    if error < -c.band:
        return result("undershoot", f"apogee {error:+.6g} m off the target, below the band +-{c.band:.6g} m")
    return result("captured", f"apogee {error:+.6g} m off the target, within +-{c.band:.6g} m")


def _number(x) -> float:
    """A recorded value as a float (summary.json writes non-finite values as strings)."""
    try:
        return float(x)
    except (TypeError, ValueError):
        return NAN


def _left_atmosphere(state, at_event: bool, c: CaptureCriteria) -> bool:
    """The state (h, v, gamma) is an exit: climbing (gamma > 0), and either located by the
    run's stop condition (at_event) or above the exit altitude."""
    h, _v, gamma = state
    if not all(map(math.isfinite, state)) or not gamma > 0.0:
        return False
    return at_event or h >= c.exit_altitude


def record_from_row(row: dict, c: CaptureCriteria, vehicle: str = "vehicle",
                    actuator: str = "actuator") -> RunRecord:
    """RunRecord of a Monte Carlo row (`montecarlo.worker.columns`): the exit.* values when the
    scenario's stop condition (the exit crossing) fired there climbing, else the final state if it
    is above the exit altitude and climbing. Signals
    read: {vehicle}.h, v, gamma, qdot, load_factor, int_abs_u, int_u2, heat_load, qdot_total,
    heat_load_total and {actuator}.saturation_time (nan when not recorded)."""
    def get(prefix, name):
        return _number(row.get(f"{prefix}.{name}", NAN))

    v = vehicle
    at = "exit" if math.isfinite(_number(row.get("exit.time", NAN))) else "final"
    state = tuple(get(at, f"{v}.{s}") for s in ("h", "v", "gamma"))
    exited = _left_atmosphere(state, at == "exit", c)
    return RunRecord(
        status=str(row.get("status", "")), error=str(row.get("error", "") or ""),
        exit=state if exited else None, min_altitude=get("min", f"{v}.h"),
        peak_heat_rate=get("max", f"{v}.qdot"), heat_load=get(at, f"{v}.heat_load"),
        peak_load_factor=get("max", f"{v}.load_factor"), int_abs_u=get(at, f"{v}.int_abs_u"),
        int_u2=get(at, f"{v}.int_u2"), saturation_time=get(at, f"{actuator}.saturation_time"),
        peak_heat_rate_total=get("max", f"{v}.qdot_total"), heat_load_total=get(at, f"{v}.heat_load_total"))


def record_from_summary(summary: dict, c: CaptureCriteria, vehicle: str = "vehicle",
                        actuator: str = "actuator") -> RunRecord:
    """RunRecord of a run's summary.json (`runner`): the located event's values when a stop
    condition on {vehicle}.h fired there climbing, else the final values if above the exit
    altitude and climbing;
    minima and maxima from its "min"/"max" entries. Same signals as `record_from_row`."""
    event = summary.get("event")
    values = event["values"] if event else summary.get("final", {})
    lows, highs = summary.get("min", {}), summary.get("max", {})

    def at(name):
        return _number(values.get(f"{vehicle}.{name}", NAN))

    def extreme(table, name):
        entry = table.get(f"{vehicle}.{name}")
        return _number(entry["value"]) if entry else NAN

    state = (at("h"), at("v"), at("gamma"))
    exited = _left_atmosphere(state, event is not None and event.get("signal") == f"{vehicle}.h", c)
    return RunRecord(
        status=str(summary.get("status", "")), error=str(summary.get("error") or ""),
        exit=state if exited else None, min_altitude=extreme(lows, "h"),
        peak_heat_rate=extreme(highs, "qdot"), heat_load=at("heat_load"),
        peak_load_factor=extreme(highs, "load_factor"), int_abs_u=at("int_abs_u"),
        int_u2=at("int_u2"), saturation_time=_number(values.get(f"{actuator}.saturation_time", NAN)),
        peak_heat_rate_total=extreme(highs, "qdot_total"), heat_load_total=at("heat_load_total"))
