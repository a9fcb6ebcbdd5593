"""A scenario's campaign outcome settings (`"montecarlo": {"outcome": {...}}`), typed and checked
once, when the scenario loads.

`OutcomeSettings` holds what classifies a run (`mission.outcome`): the target apogee, the capture
band and the floor (m), the components whose signals are classified (the vehicle's h, v, gamma, the
actuator's saturation_time) and the stated limits a benchmark counts runs above. Every reader
(campaign rows, a single run's summary, the benchmark's scorecard and plots, the corridor) takes
these fields; nothing reads the file's dictionary with defaults of its own.
"""

import math
from dataclasses import dataclass, field

from aotv_cosim.errors import InputError
from aotv_cosim.mission.outcome import CaptureCriteria

ENTRY = "montecarlo.outcome"
"""Where the settings are in a scenario file (named in error lines)."""

DEFAULT_BAND = 10e3
"""Half-width of the capture band when the scenario gives none, m."""
DEFAULT_FLOOR = 60e3
"""Undershoot floor when the scenario gives none, m (under the 78-80 km lowest points of the
seed-000 guided passes)."""


@dataclass(frozen=True)
class Limits:
    """Limits a vehicle must survive, stated by a scenario (None: not stated); a benchmark counts
    the completed runs above each (`campaigns.limits`)."""

    load_factor: float | None = None
    """Peak aerodynamic load factor, in g0 (unit 1)."""
    heat_rate: float | None = None
    """Peak stagnation heat rate, W/m2."""
    dynamic_pressure: float | None = None
    """Peak dynamic pressure, Pa."""

    def stated(self) -> dict:
        """{limit name: value} of the limits stated, in the order of the fields."""
        return {name: value for name, value in vars(self).items() if value is not None}


@dataclass(frozen=True)
class OutcomeSettings:
    """How a scenario's runs are classified (captured, skip_out, undershoot, impact, failed)."""

    target_apogee: float
    """Target apogee altitude of the exit orbit, m (default: seed 000's, 1191.154 km)."""
    band: float = DEFAULT_BAND
    """Half-width of the accepted apogee band, m (> 0)."""
    floor: float = DEFAULT_FLOOR
    """An altitude below it before the exit is an undershoot, m (>= 0)."""
    vehicle: str = "vehicle"
    """The vehicle component: its h, v, gamma (recorded) are classified."""
    actuator: str = "actuator"
    """The actuator component whose saturation_time is reported (nan when it has none)."""
    limits: Limits = field(default_factory=Limits)
    """The stated limits."""

    @property
    def criteria(self) -> CaptureCriteria:
        """The `mission.outcome.CaptureCriteria` of these settings."""
        return CaptureCriteria(self.target_apogee, self.band, self.floor)


def seed000_target() -> float:
    """Seed 000's target apogee, m: the apogee of the orbit through the Table 4.1 exit state."""
    return CaptureCriteria.seed000().target_apogee


def outcome_settings(given: dict, components, file) -> OutcomeSettings:
    """The OutcomeSettings of a scenario's `montecarlo.outcome` object `given` (already checked
    against the schema: numbers, names, known keys), defaults filled in; InputError (naming
    `file`, the scenario) for a number that is not finite or out of its range, or a vehicle or
    actuator that names no component of the system (`components`: its component names)."""
    numbers = {"target_apogee": (given.get("target_apogee", seed000_target()), 0.0, True),
               "band": (given.get("band", DEFAULT_BAND), 0.0, True),
               "floor": (given.get("floor", DEFAULT_FLOOR), 0.0, False)}
    for name, (value, low, open_low) in numbers.items():
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
                or value < low or (open_low and value == low):
            raise InputError(f"{name} is {value!r}", file=file, entry=f"{ENTRY}.{name}",
                             fix=f"give a finite number of m {'above' if open_low else 'at least'} {low:g}")
    for role in ("vehicle", "actuator"):
        if role in given and given[role] not in components:
            raise InputError(f"{role} {given[role]!r} names no component of the system", file=file,
                             entry=f"{ENTRY}.{role}", fix=f"name one of {', '.join(components)}")
    if "vehicle" not in given and "vehicle" not in components:
        raise InputError("the system has no component named 'vehicle', the default vehicle", file=file,
                         entry=ENTRY, fix=f'name the vehicle: "vehicle": one of {", ".join(components)}')
    stated = given.get("limits", {})
    for name, value in stated.items():
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
            raise InputError(f"limit {name} is {value!r}", file=file, entry=f"{ENTRY}.limits.{name}",
                             fix="give a finite positive number (SI)")
    return OutcomeSettings(target_apogee=float(numbers["target_apogee"][0]), band=float(numbers["band"][0]),
                           floor=float(numbers["floor"][0]), vehicle=given.get("vehicle", "vehicle"),
                           actuator=given.get("actuator", "actuator"),
                           limits=Limits(**{name: float(value) for name, value in stated.items()}))
