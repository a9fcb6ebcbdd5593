"""The contract of a benchmark set: what a law flown in it must provide, derived from the set's
scenarios (not written down a second time), and the check of a law against it.

A law of a set (a `--law` wiring, or a scenario of the set) must hold:

- **the plant**: the components the corridor reads as the plant from the set's wiring (the
  vehicle, its actuator and the atmosphere: `studies.corridor.plant_of`) under the same names,
  with the same FMUs and the same values of the parameters the set gives them;
- **the command**: the plant's input the guidance feeds (`actuator.command`), fed by a component
  of the law, in the set's unit;
- **the signals the set reads**: every recorded signal, stop-condition and scatter signal as an
  output of the component of that name, in the set's unit (what the scorecard classifies and counts:
  the vehicle's h, v, gamma, heat load..., the saturation time of the outcome's `actuator`, the
  bank reversals);
- **the dispersed values**: every parameter the set's dispersions draw, as a Real parameter in the
  set's unit (and the parameters the set's first scenario sets, which a `--law` wiring is flown with).

`check` reports every missing piece at once, each naming the law's own file and what is missing
(`error: my_law.json: components.bank: no component 'bank': the set records bank.saturation_time
[s] ...`). `markdown` writes the contract as the table docs/benchmark.md shows (a test keeps the two
equal).
"""

from dataclasses import dataclass

from aotv_cosim.campaigns.oracle_score import first_law
from aotv_cosim.errors import InputError, raise_if_any
from aotv_cosim.studies import corridor as core

NUMERIC = ("Real", "Integer", "Enumeration", "Boolean")
"""Output types a campaign column can hold."""


@dataclass(frozen=True)
class Need:
    """One piece of the contract: `signal` ('comp.var') as `role` ("plant", "command", "output" or
    "parameter") in `unit`, asked for by `uses` (the set's entries), meaning `description` (the
    set's FMU's own words). A plant need has `fmu` (the FMU's name) and `values` (the parameters the
    set gives); its `signal` is the component's name."""

    signal: str
    role: str
    unit: str = ""
    uses: tuple = ()
    description: str = ""
    fmu: str = ""
    guid: str = ""
    values: tuple = ()

    @property
    def component(self) -> str:
        return self.signal.split(".", 1)[0]

    @property
    def variable(self) -> str:
        return self.signal.split(".", 1)[1] if "." in self.signal else ""


def of_set(set_scenarios) -> list:
    """The contract (a list of Need, in the order plant, command, outputs, parameters) of a set's
    [(path, loaded Scenario)] (`benchmark.scenarios_of`: every scenario classifies its runs and
    gives the same columns). The plant and its command are those the corridor reads from the wiring
    of the first scenario that is not the set's oracle (`oracle_score.first_law`: a law's, as a
    `--law` wiring is flown in it; `studies.corridor.plant_of`); a set whose plant cannot be read
    that way has none in its contract."""
    first_path, first = first_law(set_scenarios)
    overridden = _scenario_parameters(first_path)
    needs = []
    try:
        plant = core.plant_of(first)
    except InputError:
        plant = None
    if plant is not None:
        for name, comp in first.system.components.items():
            if name not in plant.removed:
                needs.append(Need(name, "plant", fmu=comp.fmu.model_description.modelName, guid=comp.fmu.guid,
                                  values=tuple(sorted((k, v) for k, v in comp.parameters.items()
                                                      if f"{name}.{k}" not in overridden)),
                                  description=comp.fmu.model_description.description or ""))
        fed = "".join(f"{c.source}.{c.output}" for c in first.system.connections
                      if f"{c.target}.{c.input}" == plant.command)
        needs.append(_need(first.system, plant.command, "command", (f"fed by {fed} in {first_path.name}",)))
    outputs: dict = {}
    for signal in first.record:
        outputs.setdefault(signal, []).append("record")
    for c in first.stop_conditions:
        outputs.setdefault(c.signal, []).append("stop condition")
    for signal in first.scatter:
        outputs.setdefault(signal, []).append("exit scatter plot")
    outcome = first.outcome
    for signal, uses in outputs.items():
        comp = signal.split(".", 1)[0]
        if comp == outcome.vehicle:
            uses.append("the outcome's vehicle")
        if comp == outcome.actuator and signal.endswith(".saturation_time"):
            uses.append("the outcome's actuator: saturation time")
        if signal.endswith(".reversals") and outcome.limits.stated():
            uses.append("bank reversals of the limits")
    needs += [_need(first.system, signal, "output", tuple(uses)) for signal, uses in outputs.items()]
    parameters = {d.signal: "dispersed" for d in first.dispersions}
    parameters.update({name: f"set by {first_path.name}" for name in overridden if name not in parameters})
    needs += [_need(first.system, signal, "parameter", (why,)) for signal, why in parameters.items()]
    _check_units_alike(needs, set_scenarios)
    return needs


def _need(system, signal, role, uses) -> Need:
    variable = system.variable(signal)
    return Need(signal, role, variable.unit or "", uses, variable.description or "")


def _scenario_parameters(path) -> list:
    """The names a scenario file's "parameters" sets (a --law wiring is flown with them)."""
    from aotv_cosim.model.documents import strict_json

    return list(strict_json(path.read_text(encoding="utf-8")).get("parameters", {}))


def _check_units_alike(needs, set_scenarios) -> None:
    """InputError naming the set's scenario in which a needed signal has another unit."""
    for need in needs:
        if need.role == "plant":
            continue
        for path, scenario in set_scenarios[1:]:
            unit = scenario.system.variable(need.signal).unit or ""
            if unit != need.unit:
                raise InputError(f"{need.signal} is in {unit or 'no unit'} here, in {need.unit or 'no unit'} in "
                                 f"{set_scenarios[0][0].name}", file=path, entry="system",
                                 fix="give every law of the set the same units")


def check(needs, system, file, set_name, entry_prefix="") -> None:
    """Raise InputError (ValidationFailed for several) naming `file` (the law's own file) for every
    piece of the contract `needs` the loaded `system` lacks: a plant component missing or not the
    set's, a command not fed by the law, a signal that is no output of the component of its name, a
    dispersed value that is no Real parameter, a unit that is not the set's. `entry_prefix` goes
    before each entry (a scenario law: its system's file)."""
    problems = []
    verbs = {"command": "feeds its command", "output": "reads", "parameter": "draws"}

    def problem(cause, entry, fix):
        problems.append(InputError(cause, file=file, entry=f"{entry_prefix}{entry}", fix=fix))

    missing: dict = {}
    for need in needs:
        if need.component not in system.components:
            missing.setdefault(need.component, []).append(need)
            continue
        comp = system.components[need.component]
        if need.role == "plant":
            _check_plant(need, comp, set_name, problem)
            continue
        variable = comp.fmu.variables.get(need.variable)
        what = {"command": "input", "output": "output", "parameter": "parameter"}[need.role]
        entry = f"components.{need.component}"
        why = f"the set {set_name} {verbs[need.role]} {need.signal} [{need.unit or 'no unit'}] ({'; '.join(need.uses)})"
        if variable is None or variable.causality != what or \
                (need.role == "output" and variable.type not in NUMERIC) or \
                (need.role != "output" and variable.type != "Real"):
            has = "no" if variable is None else f"{need.variable} as {variable.causality} {variable.type}, no"
            problem(f"{need.component} ({comp.fmu_ref}) has {has} {'Real ' * (need.role != 'output')}{what} "
                    f"{need.variable}: {why}", entry, f"give {need.component} the {what} {need.variable}"
                    + (f" ({need.description})" if need.description else ""))
        elif (variable.unit or "") != need.unit:
            problem(f"{need.signal} is in {variable.unit or 'no unit'}: {why}", entry,
                    f"declare {need.signal} in {need.unit or 'no unit'}")
        elif need.role == "command" and not any(c.target == need.component and c.input == need.variable
                                                 for c in system.connections):
            problem(f"{need.signal} is not fed by your law: {why}", "connections",
                    f"connect your law's command: 'LAW.OUTPUT -> {need.signal}'")
    for component, group in missing.items():
        if group[0].role == "plant":
            need = group[0]
            problem(f"no component {component!r}: the set {set_name} flies {need.fmu} as {component} in every law",
                    "components", f"add the set's {component}: {{\"fmu\": \"{need.fmu}\", \"parameters\": "
                                  f"{dict(need.values)}}}")
            continue
        listed = ", ".join(f"{n.signal} [{n.unit or 'no unit'}] ({'; '.join(n.uses)})" for n in group)
        problem(f"no component {component!r}: the set {set_name} reads {listed}", "components",
                f"name the component of your law that provides {'it' if len(group) == 1 else 'them'} {component!r}")
    raise_if_any(problems)


def _check_plant(need, comp, set_name, problem) -> None:
    """The plant component `comp` of the law is the set's: same FMU, same parameter values."""
    entry = f"components.{need.component}"
    if comp.fmu.guid != need.guid:
        problem(f"{need.component} is {comp.fmu_ref} ({comp.fmu.model_description.modelName}): the set {set_name} "
                f"flies {need.fmu} as {need.component} in every law", entry,
                f"fly the set's plant: \"fmu\": \"{need.fmu}\"")
        return
    for name, value in need.values:
        given = comp.parameters.get(name, comp.fmu.variables[name].start if name in comp.fmu.variables else None)
        if given != value:
            problem(f"{need.component}.{name} is {given!r}: the set {set_name} flies {value!r} in every law",
                    f"{entry}.parameters.{name}", f"give {need.component} the set's {name}: {value!r}")


def markdown(needs) -> str:
    """The contract as a Markdown table (docs/benchmark.md): what, role, unit, why, meaning (a `|`
    of a description escaped)."""
    head = "| component / signal | a law must | unit | the set uses it for | meaning (the set's FMUs) |"
    lines = [head, "|---|---|---|---|---|"]
    for n in needs:
        if n.role == "plant":
            values = ", ".join(f"{k} {v:g}" if isinstance(v, float) else f"{k} {v}" for k, v in n.values)
            lines.append(f"| `{n.signal}` | hold the set's {n.fmu}{' (' + values + ')' if values else ''} | | the "
                         f"plant every law flies | {_cell(n.description)} |")
            continue
        must = {"command": "feed the input", "output": "output", "parameter": "have the Real parameter"}[n.role]
        lines.append(f"| `{n.signal}` | {must} | {n.unit or '-'} | {'; '.join(n.uses)} | {_cell(n.description)} |")
    return "\n".join(lines) + "\n"


def _cell(text: str) -> str:
    return text.replace("|", "\\|")
