"""The theoretical entry corridor of a scenario that classifies its runs: the entry flight-path
angles between which the vehicle, flying full lift up or full lift down, still exits on the target
apogee. The command (`campaigns.corridor`, runs on local workers or Dask) and the aerocapture study
(`studies.aerocapture_corridor`, runs in this process) both use this module: the plant read from
the wiring, the passes flown, the bisection.

The plant is read from the wiring, not from file names: the vehicle (the outcome's) has exactly one
input, fed by another component, in rad or m/s2, the control:

- rad: a bank-angle vehicle. It flies its own lift: sigma = 0 (full lift up), 180 deg (full lift
  down), 90 deg (no vertical lift); its L/D is C_L / C_D of its `CL` and `CD` parameters, reported,
  and `--lift-to-drag` is refused (it would be ignored).
- m/s2: a lift-acceleration vehicle (seed 000: the lift acceleration is the control and the thesis
  states no lift limit). It flies u = x L/D D/m (`ConstantLiftToDrag`, x = 1, -1 or 0 from its
  measured drag) at the L/D the user states (`--lift-to-drag`, required).

The component feeding the control is the actuator when it has an input in the same unit fed by a
component other than the vehicle (its command): the actuator is kept (its rate limits and lag
fly), and what feeds its command (the guidance, a lift-to-bank converter, everything upstream of
them that is not the vehicle or what feeds the vehicle's other inputs, such as the atmosphere) is
taken out. Without such an actuator the component feeding the control is the guidance and is
taken out. A bank-angle actuator starts at its command (`BankActuator`), so a constant bank is
flown from the entry.

Bounds (bisection on the vehicle's `gamma0`, from the scenario's own entry outward until the aim is
straddled, or over a given bracket; a shallower entry keeps more energy, so near the corridor the
apogee error grows with gamma0: far from it it need not, e.g. the seed-000 vehicle at L/D 5 flown
full lift up from -30 deg is pulled out of the atmosphere to an apogee 232 km above the target):

- steep: full lift up exits on the aim; any steeper entry undershoots whatever the guidance does;
- shallow: full lift down exits on the aim; any shallower entry skips out whatever it does.

The aim is the target apogee (`aim` "target", the textbook theoretical corridor, as AMAT computes
it) or the capture band's edges ("band": the steep bound on -band, the shallow on +band, a
slightly wider corridor). A bisection ends when the gamma0 bracket around its edge is narrower
than `angle_tolerance` (rad), or earlier when a run lands within `tolerance` (m) of the aim (when
given); the bound is the flown run nearest the aim, and the final bracket and its two apogee
errors are kept beside it. Where the apogee changes steeply across the aim (the lift-down edges:
the AFE's apogee error goes from an impact to +1400 km within 0.002 deg; the AOTV's from no exit
to a skip-out thousands of km high) no run lands near the aim, and the bracket says how sharp the
edge is. A run that never climbs back out counts as below every aim, an unbound exit orbit as
above.

The passes are flown at the scenario's step, at most `MAX_STEP`: the AOTV's steep edge (a 33 g
dive to 45 km) moves by 0.0085 deg between 1 s steps (the benchmark's, with the density held over
a step) and 0.1 s, while between 0.1 s and 0.05 s no edge of either aerocapture set moves by more
than 0.00005 deg.
"""

import json
import math
from dataclasses import dataclass
from pathlib import Path

from aotv_cosim.errors import InputError, SimulationError
from aotv_cosim.model.documents import strict_json
from aotv_cosim.status import Status

BANK, LIFT = "bank", "lift"
"""Plant kinds: a bank-angle vehicle (control in rad), a lift-acceleration vehicle (m/s2)."""
KINDS = {"rad": BANK, "m/s2": LIFT}
"""The plant kind of each unit of the vehicle's control input."""
FRACTIONS = {"lift_up": 1.0, "lift_down": -1.0, "no_vertical_lift": 0.0}
"""The vertical lift fraction cos(sigma) (or u / (L/D D/m)) of each pass flown."""
AIMS = ("target", "band")
"""Where a bound's pass exits: on the target apogee, or on the capture band's edge."""
LIFT_COMPONENT = "corridor_lift"
"""Name of the component that flies a lift-acceleration vehicle at a constant L/D."""
MAX_STEP = 0.1
"""Longest communication step the corridor's passes are flown at, s (module docstring)."""
MAX_RUNS = 80
"""Runs a bisection may take before it gives up (the angle tolerance ends it long before)."""
FIRST_STEP = 0.01
"""First step away from the scenario's entry while a bound is not yet straddled, rad (then doubled)."""
STEEPEST, SHALLOWEST = -1.5, -1e-4
"""The entry flight-path angles a search steps out to at most, rad."""


@dataclass(frozen=True)
class Plant:
    """What a corridor flies of a scenario's system (module docstring)."""

    kind: str
    """BANK or LIFT."""
    vehicle: str
    """The vehicle component (the scenario's outcome vehicle)."""
    control: str
    """The vehicle's control input, 'vehicle.sigma' or 'vehicle.u_lift'."""
    command: str
    """The input the corridor drives: the actuator's command, or the control itself."""
    removed: tuple
    """The components taken out (the guidance and what only feeds it), in wiring order."""
    lift_to_drag: float | None
    """A bank-angle vehicle's own L/D (C_L / C_D of its parameters; None without them)."""


@dataclass(frozen=True)
class Bound:
    """One bisection: its name, the pass flown (a key of FRACTIONS) and the apogee error aimed at, m."""

    name: str
    case: str
    aim: float


def bounds(aim: str, band: float, no_vertical_lift: bool = False) -> list:
    """The Bounds searched: steep (full lift up) and shallow (full lift down) on the target (aim
    "target") or on the band's edges -band / +band m ("band"); with `no_vertical_lift`, also the
    entry whose pass at no vertical lift meets the target (the centre of the control authority)."""
    edge = 0.0 if aim == "target" else band
    found = [Bound("steep", "lift_up", -edge if edge else 0.0), Bound("shallow", "lift_down", edge)]
    return found + ([Bound("no_vertical_lift", "no_vertical_lift", 0.0)] if no_vertical_lift else [])


def plant_of(scenario) -> Plant:
    """The Plant of a loaded scenario that classifies its runs; InputError naming the wiring when
    the vehicle's control or the actuator's command cannot be told, or a plant component reads the
    guidance."""
    system, vehicle = scenario.system, scenario.outcome.vehicle
    sources = system.source_of()
    fed = {inp: src for (target, inp), (src, _) in sources.items() if target == vehicle and src != vehicle}
    controls = [inp for inp in fed if system.variable(f"{vehicle}.{inp}").unit in KINDS]
    if len(controls) != 1:
        found = ", ".join(f"{inp} [{system.variable(f'{vehicle}.{inp}').unit}]" for inp in fed) or "none"
        raise InputError(f"the vehicle {vehicle!r} has {len(controls)} connected inputs in rad or m/s2 (its "
                         f"connected inputs: {found}): the corridor cannot tell its control", file=system.path,
                         entry="connections", fix="connect one steering input of the vehicle: a bank angle (rad) or "
                                                  "a lift acceleration (m/s2)")
    control = controls[0]
    unit, driver = system.variable(f"{vehicle}.{control}").unit, fed[control]
    commands = [inp for (target, inp), (src, _) in sources.items()
                if target == driver and src != vehicle and system.variable(f"{driver}.{inp}").unit == unit]
    if len(commands) > 1:
        raise InputError(f"the actuator {driver!r} has {len(commands)} inputs in {unit} fed by other components "
                         f"({', '.join(commands)}): the corridor cannot tell its command", file=system.path,
                         entry="connections", fix="give the actuator one command input")
    command = f"{driver}.{commands[0]}" if commands else f"{vehicle}.{control}"
    kept = _plant_components(sources, vehicle, control, driver if commands else None)
    removed = _guidance_components(sources, kept, sources[tuple(command.split(".", 1))][0])
    for (target, inp), (src, out) in sources.items():
        if src in removed and target in kept and f"{target}.{inp}" != command:
            raise InputError(f"{target}.{inp} of the plant reads {src}.{out} of the guidance the corridor takes out",
                             file=system.path, entry="connections",
                             fix="feed the plant (vehicle, actuator, atmosphere) from the plant only")
    lift_to_drag = None
    if KINDS[unit] == BANK and {"CL", "CD"} <= set(system.components[vehicle].fmu.variables):
        lift_to_drag = _value(scenario, f"{vehicle}.CL") / _value(scenario, f"{vehicle}.CD")
    return Plant(KINDS[unit], vehicle, f"{vehicle}.{control}", command,
                 tuple(name for name in system.components if name in removed), lift_to_drag)


def _plant_components(sources, vehicle, control, actuator) -> set:
    """The vehicle, its actuator and every component upstream of its other inputs (the atmosphere)."""
    kept = {vehicle} | ({actuator} if actuator else set())
    stack = [src for (target, inp), (src, _) in sources.items() if target == vehicle and inp != control]
    while stack:
        comp = stack.pop()
        if comp not in kept:
            kept.add(comp)
            stack += [src for (target, _), (src, _) in sources.items() if target == comp]
    return kept


def _guidance_components(sources, kept, first) -> set:
    """`first` and every component upstream of it or reading one of them, outside the plant `kept`."""
    removed, stack = set(), [first]
    while stack:
        comp = stack.pop()
        if comp in kept or comp in removed:
            continue
        removed.add(comp)
        stack += [src for (target, _), (src, _) in sources.items() if target == comp]
        stack += [target for (target, _), (src, _) in sources.items() if src == comp]
    return removed


def _value(scenario, signal) -> float:
    """A parameter's value in the loaded scenario (its wiring or scenario override, else its start)."""
    comp, var = signal.split(".", 1)
    return float(scenario.system.components[comp].parameters.get(var, scenario.system.variable(signal).start))


def lift_to_drag_flown(plant: Plant, given, file) -> float | None:
    """The L/D a lift-acceleration plant flies (`given`, the user's); None for a bank-angle plant,
    which flies its own. InputError where `given` would be ignored or is missing."""
    if plant.kind == BANK and given is not None:
        own = f"C_L/C_D = {plant.lift_to_drag:.4g} of its parameters" if plant.lift_to_drag is not None else \
            "its own lift"
        raise InputError(f"the vehicle is steered by its bank angle ({plant.control}, rad) and flies {own}: "
                         f"--lift-to-drag {given:g} would be ignored", file=file, entry="--lift-to-drag",
                         fix="leave --lift-to-drag out (set the vehicle's CL and CD to fly another L/D)")
    if plant.kind == LIFT and given is None:
        raise InputError(f"the vehicle is steered by a lift acceleration ({plant.control}, m/s2) and states no "
                         "lift limit", file=file, entry="--lift-to-drag",
                         fix="give the L/D it can fly, e.g. --lift-to-drag 5")
    return given


def gamma0_signal(scenario) -> str:
    """'vehicle.gamma0', the entry flight-path angle bisected; InputError if the vehicle has none."""
    vehicle = scenario.outcome.vehicle
    variable = scenario.system.components[vehicle].fmu.variables.get("gamma0")
    if variable is None or variable.causality != "parameter" or variable.unit != "rad":
        raise InputError(f"the vehicle {vehicle!r} has no parameter gamma0 in rad (the entry flight-path angle the "
                         "corridor bisects)", file=scenario.path, entry="montecarlo.outcome.vehicle",
                         fix="name a vehicle with an entry flight-path angle parameter gamma0")
    return f"{vehicle}.gamma0"


def write_scenarios(scenario, plant: Plant, cases, lift_to_drag, step, out, sets=None) -> dict:
    """{case: path} of the scenario (loaded, `scenario`) flown at each pass of `cases` (keys of
    FRACTIONS): its guidance taken out, the control held (module docstring), `step` s, the
    overrides `sets` ({'comp.var': value}, checked on the loaded scenario and by `check_flyable`)
    among its parameters, written to `out` as <case>.json with <case>_wiring.json."""
    path, wiring_path = Path(scenario.path), Path(scenario.system.path)
    doc = strict_json(path.read_text(encoding="utf-8"))
    wiring = strict_json(wiring_path.read_text(encoding="utf-8"))
    gone = set(plant.removed)
    components = {name: _absolute(comp, wiring_path.parent) for name, comp in wiring["components"].items()
                  if name not in gone}
    arrows = [c for c in wiring.get("connections", []) if not {_component(c, 0), _component(c, 1)} & gone]
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    paths = {}
    for case in cases:
        x = FRACTIONS[case]
        system = {"description": "", "components": json.loads(json.dumps(components)), "connections": list(arrows)}
        if plant.kind == BANK:
            comp, var = plant.command.split(".", 1)
            system["components"][comp].setdefault("parameters", {})[var] = math.acos(x)
            how = f"at sigma = {math.degrees(math.acos(x)):g} deg"
        else:
            system["components"][LIFT_COMPONENT] = {"fmu": "ConstantLiftToDrag",
                                                    "parameters": {"lift_to_drag": x * lift_to_drag}}
            system["connections"] += [f"{plant.vehicle}.drag_acc -> {LIFT_COMPONENT}.drag_acc",
                                      f"{LIFT_COMPONENT}.u -> {plant.command}"]
            how = f"at L/D = {x * lift_to_drag:g}"
        system["description"] = f"{wiring_path} with its guidance ({', '.join(plant.removed)}) taken out, flown {how}"
        (out / f"{case}_wiring.json").write_text(json.dumps(system, indent=2) + "\n")
        flown = _flown(doc, gone, scenario, step)
        flown["parameters"].update(sets or {})
        flown.update(system=f"{case}_wiring.json", description=f"{path} flown {how} (corridor)")
        (out / f"{case}.json").write_text(json.dumps(flown, indent=2) + "\n")
        paths[case] = out / f"{case}.json"
    return paths


def check_flyable(scenario, plant: Plant, sets=None) -> None:
    """InputError unless the scenario flies without the guidance: no --set value (`sets`) and no
    stop condition names a component `plant` takes out."""
    gone = set(plant.removed)
    for name in sets or {}:
        if name.split(".")[0] in gone:
            raise InputError(f"{name} is a value of the guidance the corridor takes out ({', '.join(plant.removed)})",
                             file=scenario.path, entry="--set", fix="set values of the vehicle, actuator or atmosphere")
    for condition in scenario.stop_conditions:
        if condition.signal.split(".")[0] in gone:
            raise InputError(f"stop condition on {condition.signal}, of the guidance the corridor takes out",
                             file=scenario.path, entry="stop_conditions", fix="stop the run on a vehicle signal")


def _flown(doc, gone, scenario, step) -> dict:
    """The scenario document without what names the removed components (parameters, bindings,
    records), its dispersions, expectations and plots, at a fixed step of `step` s."""
    flown = {k: v for k, v in doc.items() if k not in ("$schema", "dispersions", "dispersion_set", "expect",
                                                        "expectations", "plots", "system", "parameters", "record",
                                                        "bindings")}
    flown["parameters"] = {k: v for k, v in doc.get("parameters", {}).items() if k.split(".")[0] not in gone}
    bindings = {k: v for k, v in doc.get("bindings", {}).items()
                if k.split(".")[0] not in gone and v.split(".")[0] not in gone}
    if bindings:
        flown["bindings"] = bindings
    flown["record"] = [r for r in doc.get("record", scenario.record) if r.split(".")[0] not in gone]
    flown["step"] = {"size": step, "inputs": scenario.inputs}
    campaign = dict(doc.get("montecarlo", {}))
    campaign["scatter"] = [s for s in campaign.get("scatter", []) if s.split(".")[0] not in gone]
    for key in ("columns", "versus"):
        campaign.pop(key, None)  # the corridor draws its own plot
    campaign["outcome"] = {k: v for k, v in campaign["outcome"].items()
                           if not (k == "actuator" and v in gone)}  # its saturation time left the pass
    flown["montecarlo"] = campaign
    return flown


def _component(connection: str, side: int) -> str:
    return connection.split("->")[side].strip().split(".")[0]


def _absolute(component: dict, base: Path) -> dict:
    """The component with a relative .fmu or .py FMU reference made absolute."""
    ref = component["fmu"]
    if ref.endswith((".fmu", ".py")):
        return {**component, "fmu": str((base / ref).resolve())}
    return component


def step_flown(scenario, given) -> float:
    """The communication step of the passes, s: `given`, else the scenario's, at most MAX_STEP."""
    return given if given is not None else min(scenario.step, MAX_STEP)


class EdgeSearch:
    """One bound's bisection on the pass at `path` (module docstring). With a `bracket` (steep,
    shallow) rad its two ends are flown first and must straddle the aim; without one the search
    starts at `start` (the scenario's entry, rad) and steps away from it, FIRST_STEP then doubling,
    until the aim is straddled (within STEEPEST ... SHALLOWEST rad): the edge found is the one
    nearest the scenario's entry, where the apogee error grows with gamma0. `next()` gives the gamma0
    to fly next (None while waiting for a run, or when done), `tell(gamma0, error)` takes a run's
    apogee error (m); `result` is set when done. `fix` is what a refusal of the bracket advises."""

    def __init__(self, bound: Bound, path, start, angle_tolerance, tolerance=None, bracket=None,
                 fix="give --bracket STEEP SHALLOW around the edge"):
        self.bound, self.path, self.fix = bound, Path(path), fix
        self.angle_tolerance, self.tolerance, self.bracket = angle_tolerance, tolerance, bracket
        self.low: float | None = None
        self.high: float | None = None
        """The steepest gamma0 flown above the aim is `high`, the shallowest below it `low`."""
        self.step = FIRST_STEP
        self.errors: dict[float, float] = {}
        self.points: list = []
        self.result: dict | None = None
        self.waiting = list(bracket) if bracket is not None else [start]

    def next(self):
        return self.waiting.pop(0) if self.waiting else None

    def tell(self, gamma0, error) -> None:
        self.points.append((gamma0, error))
        self.errors[gamma0] = error
        aim = self.bound.aim
        if self.tolerance is not None and abs(error - aim) <= self.tolerance:
            self._finish(gamma0)
            return
        if self.bracket is not None and len(self.points) <= 2:
            if len(self.points) == 2:
                self._check_bracket()
            return
        if error < aim:
            self.low = gamma0 if self.low is None else max(self.low, gamma0)
        else:
            self.high = gamma0 if self.high is None else min(self.high, gamma0)
        if self.low is None or self.high is None:
            self.waiting.append(self._farther())
        elif self.high - self.low <= self.angle_tolerance:
            self._finish(min((self.low, self.high), key=lambda g: abs(self.errors[g] - aim)))
        elif len(self.points) >= MAX_RUNS:
            raise SimulationError(f"{self.bound.case}: gamma0 not within {self.angle_tolerance:g} rad of the edge "
                                  f"after {MAX_RUNS} runs (bracket [{self.low!r}, {self.high!r}] rad)",
                                  file=str(self.path), fix="give a larger --angle-tolerance")
        else:
            self.waiting.append(0.5 * (self.low + self.high))

    def _check_bracket(self) -> None:
        """InputError unless the given bracket's ends straddle the aim (steep below, shallow above)."""
        steep, shallow = self.bracket
        low_error, high_error = self.errors[steep], self.errors[shallow]
        if not low_error <= self.bound.aim <= high_error:
            raise InputError(f"{self.bound.case}: the apogee error does not cross {self.bound.aim:+g} m between "
                             f"gamma0 = {steep} and {shallow} rad ({low_error:+.6g} and {high_error:+.6g} m)",
                             file=self.path, entry="--bracket", fix=self.fix)
        self.low, self.high = steep, shallow
        self.waiting.append(0.5 * (steep + shallow))

    def _farther(self) -> float:
        """The next gamma0 away from the entry: steeper while every run is above the aim, shallower
        while every run is below it; InputError at STEEPEST or SHALLOWEST."""
        if self.low is None:
            assert self.high is not None  # a run has been flown on one side
            edge, gamma0 = STEEPEST, max(STEEPEST, self.high - self.step)
        else:
            edge, gamma0 = SHALLOWEST, min(SHALLOWEST, self.low + self.step)
        if gamma0 in self.errors:
            side = "above" if self.low is None else "below"
            flown = ", ".join(f"{g:.6g} rad: {e:+.6g} m" for g, e in sorted(self.points))
            raise InputError(f"{self.bound.case}: the apogee error stays {side} {self.bound.aim:+g} m out to "
                             f"gamma0 = {edge} rad ({flown})", file=self.path, entry="--bracket", fix=self.fix)
        self.step *= 2.0
        return gamma0

    def _finish(self, gamma0) -> None:
        """The bound is the run at gamma0; the bracket that holds the edge is kept beside it."""
        ends = [g for g in (self.low, self.high) if g is not None]
        self.result = {"gamma0": gamma0, "apogee_error": self.errors[gamma0], "edge": self.bound.aim,
                       "runs": len(self.points), "bracket": ends if len(ends) == 2 else None,
                       "bracket_errors": [self.errors[g] for g in ends] if len(ends) == 2 else None,
                       "points": sorted(self.points)}


def searches(plant: Plant, paths, found_bounds, start, angle_tolerance, tolerance=None, bracket=None) -> dict:
    """{bound name: EdgeSearch} of `found_bounds` (`bounds`) over the passes `paths` ({case: path}),
    each starting at the entry `start` (rad) or over `bracket`."""
    fix = "give --bracket STEEP SHALLOW around the edge" + (", or change --lift-to-drag" if plant.kind == LIFT else "")
    return {b.name: EdgeSearch(b, paths[b.case], start, angle_tolerance, tolerance, bracket, fix)
            for b in found_bounds}


def apogee_error(status, outcome, error, message, path, signal, gamma0) -> float:
    """The apogee error (m) of a run entered at gamma0 (its status, outcome class, apogee error
    and error message): -inf if it never exits or impacts, +inf if the exit orbit is unbound;
    SimulationError if the run failed."""
    if status not in (Status.COMPLETED, Status.IMPACT):
        raise SimulationError(f"the run at {signal} = {gamma0!r} rad failed: {message}", file=str(path),
                              fix="see the error; narrow --bracket")
    error = float(error)
    return -math.inf if outcome == "impact" or math.isnan(error) else error


def fly_in_process(found: dict, signal: str) -> dict:
    """{bound: result} of the EdgeSearches `found`, their runs flown one after the other in this
    process (the study's way; the command runs the same searches on its workers)."""
    from aotv_cosim.output.runner import simulate
    from aotv_cosim.simulation.loading import load_scenario

    for search in found.values():
        gamma0 = search.next()
        while gamma0 is not None:
            summary = simulate(load_scenario(search.path, {signal: gamma0})).summary
            outcome = summary.outcome
            assert outcome is not None  # the corridor's scenarios state an outcome (`write_scenarios`)
            search.tell(gamma0, apogee_error(summary.status, outcome["class"], outcome["apogee_error"],
                                             summary.error, search.path, signal, gamma0))
            gamma0 = search.next()
    return {name: search.result for name, search in found.items()}


def nominal_gamma0(scenario) -> float:
    """The scenario's own entry flight-path angle, rad."""
    return _value(scenario, gamma0_signal(scenario))


def undispersed(scenario) -> dict:
    """{signal: value} of every value the scenario disperses, as the corridor flies it (its wiring's,
    the scenario's or a --set value; the bisected gamma0 left out): the passes fly no dispersion."""
    skip = gamma0_signal(scenario)
    return {d.signal: _value(scenario, d.signal) for d in scenario.dispersions if d.signal != skip}
