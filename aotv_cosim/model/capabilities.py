"""What the FMUs of a scenario declare about how they may be run (FMI 2.0 CoSimulation
capability flags, DefaultExperiment), checked against what the master will do with them.

- canHandleVariableCommunicationStepSize="false": the FMU is only ever given the scenario's step.
  Error-controlled steps are refused, and so is a stop time that is not a whole number of steps
  after the start (the master would shorten the last step). A stop condition's crossing is
  interpolated between communication points, never stepped to, so it does not shorten a step.
- canBeInstantiatedOnlyOncePerProcess="true": a second component of the same FMU is refused
  (the master runs every component in one process).
- DefaultExperiment: a scenario without start, stop or step takes it from its FMUs, which must
  agree (`default_experiment`).

The other flags need nothing of the master or are met by what it always does: it provides the
memory callbacks (used or not: canNotUseMemoryManagementFunctions), calls fmi2DoStep
synchronously (canRunAsynchronuously), gives no input derivatives (canInterpolateInputs,
maxOutputDerivativeOrder), saves FMU states only with a tolerance, where canGetAndSetFMUstate is
checked, and never serializes them (canSerializeFMUstate). needsExecutionTool: the master loads
the FMU's binary as any importer does; an FMU whose tool is missing fails at instantiation with
its own message.
"""

import math

from aotv_cosim.errors import InputError, raise_if_any

WHOLE_STEPS = 1e-9
"""Relative tolerance on (stop - start) / step being a whole number for a fixed-step FMU."""

EXPERIMENT = (("start", "startTime"), ("stop", "stopTime"), ("step", "stepSize"))
"""Scenario key -> DefaultExperiment attribute."""


def fixed_step_components(system) -> list:
    """Names of the components whose FMU declares canHandleVariableCommunicationStepSize false."""
    return [name for name, comp in system.components.items()
            if not comp.fmu.model_description.coSimulation.canHandleVariableCommunicationStepSize]


def default_experiment(system, path, doc: dict, given: dict) -> dict:
    """{"start", "stop", "step"} (s) the scenario document `doc` lacks and the command line did not
    `given`, from its FMUs' DefaultExperiment; InputError when they disagree, or when none gives
    a stop time or a step that is needed (a missing start is 0, FMI's default)."""
    found = {}
    for key, attribute in EXPERIMENT:
        if key in doc or given.get(key) is not None:
            continue
        values: dict = {}
        for name, comp in system.components.items():
            experiment = comp.fmu.model_description.defaultExperiment
            text = getattr(experiment, attribute, None) if experiment is not None else None
            if text is not None:
                values.setdefault(float(text), []).append(name)
        if len(values) > 1:
            told = "; ".join(f"{', '.join(names)}: {value:g} s" for value, names in values.items())
            raise InputError(f"no \"{key}\" and the FMUs' DefaultExperiment {attribute} disagree ({told})",
                             file=path, entry=key, fix=f"give \"{key}\" in s in the scenario")
        if values:
            found[key] = next(iter(values))
        elif key != "start":
            raise InputError(f"no \"{key}\" and no FMU of the system gives a DefaultExperiment {attribute}",
                             file=path, entry=key, fix=f"give \"{key}\" in s in the scenario")
    return found


def check_capabilities(scenario) -> None:
    """Refuse what the scenario would ask of an FMU that its capability flags exclude."""
    s = scenario
    problems = []
    fixed = fixed_step_components(s.system)
    if fixed and s.step_control is not None:
        problems.append(InputError(f"{', '.join(fixed)} cannot vary its communication step "
                                   "(canHandleVariableCommunicationStepSize is false), which "
                                   "error-controlled steps need", file=s.path, entry="step.tolerance",
                                   fix="give a fixed step size"))
    elif fixed:
        n = (s.stop - s.start) / s.step
        if abs(n - round(n)) > WHOLE_STEPS * max(1.0, n):
            problems.append(InputError(f"{', '.join(fixed)} cannot vary its communication step "
                                       f"(canHandleVariableCommunicationStepSize is false) and stop - start = "
                                       f"{s.stop - s.start:g} s is {n:.6g} steps of {s.step:g} s", file=s.path,
                                       entry="stop", fix=f"give a stop time start + a whole number of steps, "
                                       f"e.g. {s.start + max(1, math.floor(n)) * s.step:g}"))
    seen: dict = {}
    for name, comp in s.system.components.items():
        cs = comp.fmu.model_description.coSimulation
        if cs.canBeInstantiatedOnlyOncePerProcess:
            key = (comp.fmu.guid, cs.modelIdentifier)
            if key in seen:
                problems.append(InputError(f"{seen[key]} and {name} are two instances of {cs.modelIdentifier}, "
                                           "which can be instantiated only once per process "
                                           "(canBeInstantiatedOnlyOncePerProcess)", file=s.system.path,
                                           entry=f"components.{name}", fix="keep one component of this FMU"))
            seen.setdefault(key, name)
    raise_if_any(problems)
