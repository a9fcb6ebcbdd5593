"""Scenario file -> validated Scenario: system, times, overrides, stop conditions, records, checks."""

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

from aotv_cosim.errors import InputError, raise_if_any
from aotv_cosim.model.capabilities import check_capabilities, default_experiment
from aotv_cosim.model import bindings as _bindings
from aotv_cosim.model.dispersion_sets import dispersion_entries
from aotv_cosim.model.documents import load_document
from aotv_cosim.model.fmu_file import FmuResolver
from aotv_cosim.model.outcome_settings import OutcomeSettings, outcome_settings
from aotv_cosim.model.ranges import check_dispersion
from aotv_cosim.model.run_size import check_run_size
from aotv_cosim.model.step_control import StepControl, step_control
from aotv_cosim.model.system import System, load_system
from aotv_cosim.model.variable_types import DISCRETE, enumeration_value
from aotv_cosim.paths import regular_file, resolved

MAX_STEPS = 1e9
"""Most communication points a scenario may ask for: more is a typing error (a step in ms, not s)."""


@dataclass(frozen=True)
class StopCondition:
    """Stop when `signal` crosses `threshold` in `direction` ('up', 'down' or 'either'), or,
    with `threshold` None, when the value of a discrete signal (Integer, Boolean, Enumeration,
    String) changes from one communication point to the next."""

    signal: str
    threshold: float | None
    direction: str = "either"


def crossing(before, now, threshold, direction):
    """None, or whether a stop condition's signal crossed `threshold` going up from `before` to
    `now` (direction 'up', 'down' or 'either'; landing on the threshold counts). A `threshold`
    None stands for any change of a discrete signal: whether it went up, None if unchanged."""
    if threshold is None:
        return None if now == before else now > before
    up = before < threshold <= now
    if up and direction != "down":
        return True
    if before > threshold >= now and direction != "up":
        return False
    return None


@dataclass(frozen=True)
class Expectation:
    """A checked value: `signal` at end/min/max/event/time must equal `value` within tolerance
    (a number), or exactly (a Boolean, String or Enumeration value, an integer without tolerance)."""

    signal: str
    at: object
    value: float
    source: str
    tolerance: float | None = None
    rel_tolerance: float | None = None
    note: str = ""

    def allowed_error(self) -> float:
        """Largest accepted |measured - value|: the larger of the absolute and relative bounds."""
        bounds = [self.tolerance or 0.0, (self.rel_tolerance or 0.0) * abs(self.value)]
        return max(bounds)


@dataclass(frozen=True)
class Dispersion:
    """A Monte Carlo distribution of one Real parameter `signal` ('component.variable').

    kind: 'uniform' (low, high), 'normal' (mean, std) or 'truncated_normal' (mean, std, low, high);
    `campaigns.draws` samples it.
    """

    signal: str
    kind: str
    mean: float | None = None
    std: float | None = None
    low: float | None = None
    high: float | None = None


@dataclass
class Scenario:
    path: Path
    system: System
    start: float
    stop: float
    step: float
    algorithm: str = "gauss-seidel"
    stop_conditions: list = field(default_factory=list)
    record: list = field(default_factory=list)
    record_every: int = 1
    expectations: list = field(default_factory=list)
    plots: list = field(default_factory=list)
    description: str = ""
    inputs: str = "held"
    """How delayed inputs are held over a step: 'held' (zero-order hold) or 'extrapolated'."""
    step_control: "StepControl | None" = None
    """Error-controlled steps (`model.step_control`); None: the fixed step `step`."""
    dispersions: list = field(default_factory=list)
    scatter: list = field(default_factory=list)
    outcome: "OutcomeSettings | None" = None
    """Campaign outcome settings (`model.outcome_settings`): runs are classified when given."""
    oracle: bool = False
    """The scenario flies its set's per-run oracle (`"montecarlo": {"oracle": true}`: the best pass
    each run allows, e.g. OracleBankGuidance), not a law: a benchmark scores the set's laws against
    its rows, run by run (`campaigns.oracle_score`)."""
    report_columns: list = field(default_factory=list)
    """Campaign columns of the report's table and histograms (`campaigns.report`)."""
    versus: list = field(default_factory=list)
    """Campaign (input, output) column pairs plotted against each other."""
    skipped: list = field(default_factory=list)
    """Expectations not checked because start or stop was overridden (see `load_scenario`)."""
    step_timeout: "float | None" = None
    """Wall-clock limit of one communication step, s (`simulation.watchdog`); None: no limit."""
    bindings: dict = field(default_factory=dict)
    """{target: source} parameters that take another parameter's value in every run (`model.bindings`)."""


def load_scenario(path, sets=None, step=None, start=None, stop=None, *, fmus: FmuResolver) -> Scenario:
    """Load a scenario; `sets` ({'comp.var': value}, from --set), `step`, `start` and `stop`
    (s, from --step, --start, --stop) override the file. `fmus` gives the wiring's FMU files
    (`fmu_file.FmuResolver`; `simulation.loading` gives the one that builds them when missing).

    With start or stop overridden the run is another experiment: the expectations measured at
    the end, a minimum, a maximum or a time are not checked (they are listed in `skipped`);
    those at the stop condition's event still are. An .ssp archive is a scenario too: its
    system over its default experiment.
    """
    path = resolved(path, what="scenario file")
    if path.suffix == ".ssp":
        from aotv_cosim.model.ssp_load import scenario_document

        doc = scenario_document(path, step_given=step is not None)
    else:
        doc = load_document(path, "scenario")
    system_path = resolved(path.parent / doc["system"], file=path, entry="system", what="wiring file")
    try:
        regular_file(system_path, what="wiring file", file=path, entry="system")
    except InputError as exc:
        raise InputError(f"wiring file {exc.cause.removeprefix('file ')}", file=path, entry="system",
                         fix="give the wiring file's path relative to the scenario") from None
    overrides = dict(doc.get("parameters", {}))
    system = load_system(system_path, overrides, overrides_file=path, fmus=fmus) if not sets else \
        load_system(system_path, {**overrides, **sets}, overrides_file=f"{path} (with --set)", fmus=fmus)
    expectations = [Expectation(e["signal"], e["at"], _expected(e["value"]), e["source"],
                                e.get("tolerance"), e.get("rel_tolerance"), e.get("note", ""))
                    for e in doc.get("expectations", [])]
    retimed = start is not None or stop is not None
    doc = {**default_experiment(system, path, doc, given={"start": start, "stop": stop, "step": step}), **doc}
    options = _step_options(doc)
    scenario = Scenario(
        path=path, system=system, start=float(doc.get("start", 0.0) if start is None else start),
        stop=float(doc["stop"] if stop is None else stop),
        step=float(step if step is not None else options["size"]),
        inputs=options.get("inputs", "extrapolated" if "tolerance" in options else "held"),
        step_control=step_control(options, float(options["size"]), path)
        if step is None and isinstance(doc.get("step"), dict) else None,
        algorithm=doc.get("algorithm", "gauss-seidel"),
        stop_conditions=[StopCondition(c["signal"], float(c["crosses"]) if "crosses" in c else None,
                                       c.get("direction", "either"))
                         for c in doc.get("stop_conditions", [])],
        record=list(doc.get("record", system.outputs())),
        record_every=int(doc.get("record_every", 1)),
        expectations=[e for e in expectations if not retimed or e.at == "event"],
        skipped=[e for e in expectations if retimed and e.at != "event"],
        plots=list(doc.get("plots", [])),
        description=doc.get("description", ""),
        dispersions=[Dispersion(signal, d["distribution"], d.get("mean"), d.get("std"), d.get("low"),
                                d.get("high")) for signal, d in dispersion_entries(doc, path).items()],
        scatter=list(doc.get("montecarlo", {}).get("scatter", [])),
        outcome=_outcome(doc, system, path),
        oracle=doc.get("montecarlo", {}).get("oracle", False),
        report_columns=list(doc.get("montecarlo", {}).get("columns", [])),
        versus=[tuple(p) for p in doc.get("montecarlo", {}).get("versus", [])],
        step_timeout=doc.get("step_timeout"),
    )
    scenario.bindings = _bindings.checked(doc.get("bindings", {}), system, path, given={**overrides, **(sets or {})},
                                          dispersed=[d.signal for d in scenario.dispersions])
    check_times(scenario)
    check_capabilities(scenario)
    _check_signals(scenario, doc)
    scenario.expectations = [_enumerated(scenario.system, e) for e in scenario.expectations]
    return scenario


def _outcome(doc, system, path) -> "OutcomeSettings | None":
    """The scenario's typed outcome settings, or None when it does not classify its runs."""
    given = doc.get("montecarlo", {}).get("outcome")
    return None if given is None else outcome_settings(given, list(system.components), path)


def _enumerated(system, e: Expectation) -> Expectation:
    """`e` with an Enumeration item's name replaced by its integer."""
    var = system.variable(e.signal)
    if var.type != "Enumeration" or not isinstance(e.value, str):
        return e
    comp = system.components[e.signal.split(".", 1)[0]]
    return replace(e, value=float(enumeration_value(comp.fmu, var.name, e.value)))


def _expected(value):
    """An expectation's value: a number as a float, a Boolean or a String (or an Enumeration
    item's name) as given."""
    return value if isinstance(value, (bool, str)) else float(value)


NUMERIC = ("Real", "Integer", "Enumeration", "Boolean")
"""Types a plot can draw (a Boolean as 0/1)."""

UNSAFE_IN_COLUMNS = (",", '"', "\n", "\r")
"""Characters a recorded signal's name may not hold: timeseries.csv's header is the names."""


def _step_options(doc) -> dict:
    """The scenario's "step" as an object: a bare number is {"size": number}."""
    step = doc.get("step")  # an .ssp without a step needs --step (checked when it is read)
    return step if isinstance(step, dict) else {"size": step}


def check_times(s: Scenario):
    """Raise InputError when the scenario's times cannot run: a step that is not positive, a stop
    not after the start, too many communication points or rows, an expectation outside the span.
    Called on load and by the API after it overrides the times of a loaded scenario."""
    problems = []
    if not math.isfinite(s.step) or not s.step > 0:
        problems.append(InputError(f"step must be positive, got {s.step}", file=s.path, entry="step",
                                   fix="give a communication step in s, e.g. 0.1"))
    elif not s.stop > s.start:
        problems.append(InputError(f"stop ({s.stop}) must be after start ({s.start})", file=s.path,
                                   entry="stop", fix="give a stop time later than the start time"))
    elif (s.stop - s.start) / s.step > MAX_STEPS:
        problems.append(InputError(f"(stop - start) / step = {(s.stop - s.start) / s.step:.3g} "
                                   f"communication points, more than {MAX_STEPS:.0e}", file=s.path,
                                   entry="step", fix="give a larger step or a shorter time span"))
    if not problems:
        problems += check_run_size(s)
    for k, e in enumerate(s.expectations):
        if not isinstance(e.at, str) and not s.start <= e.at <= s.stop:
            problems.append(InputError(f"time {e.at} s is outside the run [{s.start}, {s.stop}] s",
                                       file=s.path, entry=f"expectations[{k}].at",
                                       fix="give a time between start and stop, or end/min/max/event"))
    raise_if_any(problems)


def _check_signals(s: Scenario, doc):
    outputs = set(s.system.outputs())
    problems = []

    def check(signal, entry, types=None, use=""):
        if signal in outputs:
            kind = s.system.variable(signal).type
            if types is not None and kind not in types:
                problems.append(InputError(f"{signal} is {_a(kind)} {kind}: {use} needs "
                                           f"{' or '.join(types)} outputs", file=s.path, entry=entry,
                                           fix=f"use {_a(types[0])} {' or '.join(types)} output"))
            elif any(c in signal for c in UNSAFE_IN_COLUMNS):
                problems.append(InputError(f"{signal!r} holds a comma, quote or line break, which a "
                                           "timeseries.csv column name cannot", file=s.path,
                                           entry=entry if "record" in doc or not entry.startswith("record")
                                           else f"{entry} (default: every output)",
                                           fix="give \"record\" without it (rename the FMU variable to record it)"))
            return
        comp = signal.split(".", 1)[0]
        known = [o for o in sorted(outputs) if o.startswith(comp + ".")]
        fix = f"use an output: {', '.join(known)}" if known else \
            f"use a component of the system: {', '.join(s.system.components)}"
        problems.append(InputError(f"{signal} is not an output of the system", file=s.path,
                                   entry=entry, fix=fix))

    for k, c in enumerate(s.stop_conditions):
        if c.threshold is None:
            check(c.signal, f"stop_conditions[{k}].signal", DISCRETE, "a stop condition on a change")
        else:
            check(c.signal, f"stop_conditions[{k}].signal", ("Real", "Integer"), "a stop condition on a crossing")
        if c.threshold is None and s.step_control is not None:
            problems.append(InputError("a stop condition on a change with error-controlled steps: a change "
                                       "is not located inside a step", file=s.path,
                                       entry=f"stop_conditions[{k}]",
                                       fix="give a fixed step size, or stop on a crossing"))
    if s.step_control is not None:
        for signal in s.step_control.tolerance:
            check(signal, f"step.tolerance.{signal}", ("Real",), "an error tolerance")
        stateless = [name for name, comp in s.system.components.items()
                     if not comp.fmu.model_description.coSimulation.canGetAndSetFMUstate]
        if stateless:
            problems.append(InputError(f"{', '.join(stateless)} cannot save and restore its state "
                                       "(canGetAndSetFMUstate is false), which a rejected step needs",
                                       file=s.path, entry="step.tolerance",
                                       fix="give a fixed step size, or use FMUs that declare canGetAndSetFMUstate"))
    for k, signal in enumerate(s.record):
        check(signal, f"record[{k}]")
    for k, e in enumerate(s.expectations):
        check(e.signal, f"expectations[{k}].signal")
        if e.signal in outputs:
            problems += _check_expected(s, e, f"expectations[{k}]")
        if e.at == "event" and not s.stop_conditions:
            problems.append(InputError("'event' needs a stop condition", file=s.path,
                                       entry=f"expectations[{k}].at", fix="add stop_conditions or use 'end'"))
    for d in s.dispersions:
        comp, _, var = d.signal.partition(".")
        variable = s.system.components[comp].fmu.variables.get(var) if comp in s.system.components else None
        if variable is None or variable.causality != "parameter" or variable.type != "Real":
            problems.append(InputError(f"{d.signal} is not a Real parameter of the system", file=s.path,
                                       entry=f"dispersions.{d.signal}",
                                       fix="disperse a Real parameter (initial states are parameters)"))
        elif d.low is not None and not d.low < d.high:
            problems.append(InputError(f"low ({d.low}) must be below high ({d.high})", file=s.path,
                                       entry=f"dispersions.{d.signal}", fix="swap or widen the bounds"))
        else:
            problems += check_dispersion(s.system.components[comp].fmu, var, d, file=s.path,
                                         entry=f"dispersions.{d.signal}")
    for k, signal in enumerate(s.scatter):
        check(signal, f"montecarlo.scatter[{k}]", NUMERIC, "a scatter plot")
    if s.outcome is not None:
        vehicle = s.outcome.vehicle
        missing = [f"{vehicle}.{n}" for n in ("h", "v", "gamma") if f"{vehicle}.{n}" not in s.record]
        if missing:
            problems.append(InputError(f"classifying runs needs {', '.join(missing)} recorded", file=s.path,
                                       entry="montecarlo.outcome", fix=f"add {', '.join(missing)} to record"))
        problems += _check_outcome_actuator(s, doc, outputs)
    for k, p in enumerate(s.plots):
        for signal in p["signals"] + ([p["x"]] if p.get("x", "time") != "time" else []):
            check(signal, f"plots[{k}]", NUMERIC, "a plot")
    raise_if_any(problems)


def _check_outcome_actuator(s: Scenario, doc, outputs) -> list:
    """An outcome `actuator` the scenario names must report what it is named for: its
    saturation_time output, recorded (the default, "actuator", may have none: the column is then
    nan)."""
    if "actuator" not in doc.get("montecarlo", {}).get("outcome", {}):
        return []
    assert s.outcome is not None  # the document names an outcome actuator, so the scenario has an outcome
    signal = f"{s.outcome.actuator}.saturation_time"
    if signal not in outputs:
        return [InputError(f"{s.outcome.actuator} has no output saturation_time, which the outcome reports as the "
                           "actuator's saturation time", file=s.path, entry="montecarlo.outcome.actuator",
                           fix="name the component that outputs saturation_time (s), or leave actuator out")]
    if signal not in s.record:
        return [InputError(f"{signal} is not recorded: the outcome's saturation time would be nan", file=s.path,
                           entry="montecarlo.outcome.actuator", fix=f"add {signal} to record")]
    return []


def _a(word: str) -> str:
    """The indefinite article for `word` ('an Integer', 'a Real')."""
    return "an" if word[:1].lower() in "aeiou" else "a"


def _check_expected(s: Scenario, e: Expectation, entry) -> list:
    """Problems with an expectation's value for its signal's type: a Boolean wants true/false, a
    String a text, an Enumeration an item's integer or name, a number a tolerance; min and max
    are measured on numbers only."""
    var = s.system.variable(e.signal)
    comp = s.system.components[e.signal.split(".", 1)[0]]
    if var.type == "Enumeration":
        value = int(e.value) if isinstance(e.value, float) and e.value.is_integer() else e.value
        ok = not isinstance(e.value, bool) and enumeration_value(comp.fmu, var.name, value) is not None
    elif var.type == "Boolean":
        ok = isinstance(e.value, bool)
    elif var.type == "String":
        ok = isinstance(e.value, str)
    else:
        ok = isinstance(e.value, float)
    if not ok:
        return [InputError(f"{e.signal} is {_a(var.type)} {var.type}, expected value {e.value!r}", file=s.path,
                           entry=f"{entry}.value", fix={"Boolean": "give true or false", "String": "give a text",
                                                       "Enumeration": "give an item's integer or name"}.get(
                               var.type, "give a number"))]
    if isinstance(e.value, float) and e.tolerance is None and e.rel_tolerance is None and var.type == "Real":
        return [InputError("a Real expectation needs a tolerance", file=s.path, entry=entry,
                           fix="give tolerance or rel_tolerance")]
    if var.type in ("String", "Boolean") and e.at in ("min", "max"):
        return [InputError(f"{e.at} of {_a(var.type)} {var.type} is not defined", file=s.path, entry=f"{entry}.at",
                           fix="check it at end, event or a time")]
    return []
