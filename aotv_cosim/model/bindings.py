"""Scenario bindings: a parameter that takes another parameter's value, run by run.

`"bindings": {"oracle.CL": "vehicle.CL", ...}` in a scenario means: once the wiring's values, the
scenario's overrides (`parameters`, --set) and the run's Monte Carlo draws are applied, the
parameter on the left takes the value of the parameter on the right. A law that is to know the
truth of each dispersed run (the per-run oracle, `guidance.oracle_bank`) is told it this way,
without the dispersion set naming it. Data only: nothing is evaluated.

Checked when the scenario is loaded (`checked`): both sides are parameters of the system, of the
same type and declared unit; the bound parameter is not also given by the scenario, --set or a
dispersion (it would be overwritten), nor itself the source of a binding. Applied by the master
to every run (`bound_values`), so single runs and campaign workers (local and Dask) alike.
"""

from aotv_cosim.errors import InputError, raise_if_any


def _parameter(system, signal, file, entry):
    """(variable, problem): the parameter `signal` of the system, or an InputError."""
    comp, _, name = signal.partition(".")
    component = system.components.get(comp)
    if component is None:
        return None, InputError(f"{signal}: no component {comp!r} in the system", file=file, entry=entry,
                                fix=f"use a component of the system: {', '.join(system.components)}")
    var = component.fmu.variables.get(name)
    if var is None or var.causality != "parameter":
        known = [v.name for v in component.fmu.variables.values() if v.causality == "parameter"]
        what = "not a variable" if var is None else f"{var.causality}, not a parameter"
        return None, InputError(f"{signal} is {what} of {comp}", file=file, entry=entry,
                                fix=f"bind a parameter: {', '.join(known)}")
    return var, None


def checked(bindings: dict, system, file, given=(), dispersed=()) -> dict:
    """The scenario's bindings {target: source} after the checks of the module docstring (raises
    InputError with every problem). given: the signals the scenario's parameters and --set give;
    dispersed: the dispersed signals."""
    problems = []
    for target, source in bindings.items():
        entry = f"bindings.{target}"
        target_var, problem = _parameter(system, target, file, entry)
        problems += [problem] if problem else []
        source_var, problem = _parameter(system, source, file, entry)
        problems += [problem] if problem else []
        if problem is None and target_var is not None:
            if target == source:
                problems.append(InputError(f"{target} is bound to itself", file=file, entry=entry,
                                           fix="bind it to another parameter"))
            elif (target_var.type, target_var.unit) != (source_var.type, source_var.unit):
                problems.append(InputError(
                    f"{target} is {target_var.type} [{target_var.unit or '-'}], {source} is {source_var.type} "
                    f"[{source_var.unit or '-'}]", file=file, entry=entry,
                    fix="bind parameters of the same type and unit"))
        if target in given or target in dispersed:
            by = "a dispersion" if target in dispersed else "the scenario's parameters or --set"
            problems.append(InputError(f"{target} is also given by {by}, which the binding would overwrite",
                                       file=file, entry=entry, fix=f"give {source} instead, or drop the binding"))
        if target in bindings.values():
            problems.append(InputError(f"{target} is bound and is the source of another binding", file=file,
                                       entry=entry, fix="bind every parameter to the original source"))
    raise_if_any(problems)
    return dict(bindings)


def _typed(var, value):
    """A start value of the modelDescription (text) as the variable's Python value."""
    if not isinstance(value, str):
        return value
    if var.type == "Real":
        return float(value)
    if var.type in ("Integer", "Enumeration"):
        return int(value)
    if var.type == "Boolean":
        return value.strip().lower() in ("true", "1")
    return value


def bound_values(scenario, overrides: dict) -> dict:
    """{target: value} of the scenario's bindings for a run with the `overrides` ({'comp.var':
    value}, the draws): the source's drawn value, else its value in the system (the wiring with
    the scenario's overrides), else its FMU's start value."""
    values = {}
    system = scenario.system
    for target, source in getattr(scenario, "bindings", {}).items():
        if source in overrides:
            values[target] = overrides[source]
            continue
        comp, name = source.split(".", 1)
        component = system.components[comp]
        var = component.fmu.variables[name]
        values[target] = _typed(var, component.parameters.get(name, var.start))
    return values
