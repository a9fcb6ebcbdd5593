"""Wiring file -> validated System: components, FMUs, parameter values, connections.

FMU files are read by `fmu_file`; the stepping order derived from the connections is `ordering`'s.

Checks made on load, each reported with the file and the entry: unknown component or variable,
causality (an output feeds an input), type and declared unit agreement, at most one source per
input, every input connected or given a value, values of the right type, and no loop of direct
feedthrough. Feedthrough is read per variable from the FMUs' ModelStructure (`Outputs`
dependencies; none declared means the output depends on every input), so a vehicle whose heating
output depends on the density input does not form a loop with the atmosphere whose density
depends on the vehicle's altitude: only chains of same-instant dependencies do.
"""

import difflib
import math
import re
from dataclasses import dataclass, field, replace
from pathlib import Path

from aotv_cosim.model.documents import check_document, load_document
from aotv_cosim.errors import AotvError, InputError, raise_if_any
from aotv_cosim.model.fmu_file import FmuInfo, FmuResolver, Variable, read_fmu, resolve_fmu
from aotv_cosim.paths import resolved
from aotv_cosim.model.ranges import check_range
from aotv_cosim.model.variable_types import (FLOAT64_CALLS, INTEGER_RANGE, declared_type_name,
                                             enumeration_value, items, lossless)
from aotv_cosim.model.ssp_load import read_ssp


@dataclass
class Component:
    name: str
    fmu_ref: str
    fmu: FmuInfo
    parameters: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Connection:
    """output -> input; `as_type` "Real" when an Integer or Boolean output feeds a Real input
    (written 'a.k -> b.u (as Real)'): the input gets the integer, or 0.0/1.0, as a Real."""

    source: str
    output: str
    target: str
    input: str
    as_type: str | None = None

    def __str__(self):
        text = f"{self.source}.{self.output} -> {self.target}.{self.input}"
        return f"{text} (as {self.as_type})" if self.as_type else text


@dataclass
class System:
    """A validated wiring: components in file order and their connections."""

    path: Path
    components: dict
    connections: list
    warnings: list = field(default_factory=list)
    """What the wiring leaves uncertain without being wrong (a unit on one side of a connection)."""

    def variable(self, signal: str) -> Variable:
        comp, var = signal.split(".", 1)
        return self.components[comp].fmu.variables[var]

    def outputs(self):
        """Every output signal 'component.variable', in component and declaration order."""
        return [f"{c.name}.{v.name}" for c in self.components.values()
                for v in c.fmu.variables.values() if v.causality == "output"]

    def source_of(self):
        """{(target, input): (source, output)} for every connection."""
        return {(c.target, c.input): (c.source, c.output) for c in self.connections}

    def connected_feedthrough(self, comp, output):
        """The connected inputs of `comp` that `output` depends on at the same instant."""
        deps = self.components[comp].fmu.feedthrough.get(output, ())
        return {i for i in deps if any(c.target == comp and c.input == i for c in self.connections)}

CONVERSION = re.compile(r"\s*\(as (\w+)\)\s*$")
"""The explicit conversion written after a connection: ' (as Real)'."""


def parse_connection(text: str, *, file=None, entry=None) -> Connection:
    """'source.output -> target.input', optionally followed by ' (as Real)' (as the schema
    checked it) -> Connection."""
    conversion = CONVERSION.search(text)
    as_type = conversion.group(1) if conversion else None
    body = text[:conversion.start()] if conversion else text
    sides = [s.strip() for s in body.split("->")]
    if len(sides) != 2 or not all("." in side for side in sides) or as_type not in (None, "Real"):
        raise InputError(f"cannot read connection {text!r}", file=file, entry=entry,
                         fix="write one 'source.output -> target.input' per entry, followed by "
                             "' (as Real)' to feed an Integer or Boolean output to a Real input")
    source, output = sides[0].split(".", 1)
    target, inp = sides[1].split(".", 1)
    return Connection(source, output, target, inp, as_type)


def check_value(var: Variable, value, *, file, entry, fmu=None):
    """Problems with giving `value` to variable `var` (type, finiteness, causality); an
    Enumeration (of the FmuInfo `fmu`) takes an item's integer or name."""
    if var.causality not in ("parameter", "input"):
        return [InputError(f"{var.name} is {_a(var.causality)} {var.causality}, it cannot be given a value",
                           file=file, entry=entry, fix="set a parameter or an unconnected input")]
    if var.type == "Enumeration":
        if fmu is not None and enumeration_value(fmu, var.name, value) is not None:
            return []
        known = items(fmu, var.name) if fmu is not None else {}
        listed = ", ".join(f"{v} ({n!r})" for n, v in known.items())
        return [InputError(f"{var.name} is an Enumeration, got {_shown(value)}", file=file, entry=entry,
                           fix=f"give one of its items by integer or name: {listed}")]
    ok = {"Real": isinstance(value, (int, float)) and not isinstance(value, bool),
          "Integer": isinstance(value, int) and not isinstance(value, bool),
          "Boolean": isinstance(value, bool),
          "String": isinstance(value, str)}.get(var.type, False)
    declared = var.fmi_type
    if not ok:
        return [InputError(f"{var.name} is {declared}, got {_shown(value)}", file=file, entry=entry,
                           fix=f"give {_a(declared)} {declared} value" + (f" in {var.unit}" if var.unit else ""))]
    if var.type == "Real" and not math.isfinite(value):
        return [InputError(f"{var.name} must be finite, got {value!r}", file=file, entry=entry,
                           fix="give a finite number")]
    if declared == "Float32" and abs(value) > FLOAT32_MAX:
        return [InputError(f"{var.name} is a Float32, got {value!r}", file=file, entry=entry,
                           fix=f"give a number within +-{FLOAT32_MAX:.8g}")]
    if declared == "Binary":
        return [] if _hexadecimal(value) else [
            InputError(f"{var.name} is Binary, got {_shown(value)}", file=file, entry=entry,
                       fix="give its bytes as hexadecimal text, two digits a byte, e.g. '666f6f'")]
    if var.type == "String" and ("\0" in value or not _utf8(value)):
        return [InputError(f"{var.name} is a String, got {_shown(value)} (a NUL character or text that is not "
                           "UTF-8)", file=file, entry=entry,
                           fix="give UTF-8 text without NUL characters (an FMI String is a NUL-ended UTF-8 C string)")]
    if var.type == "Integer":
        low, high = INTEGER_RANGE[declared]
        if not low <= value <= high:
            what = "a 32-bit Integer" if declared == "Integer" else _a(declared) + " " + declared
            return [InputError(f"{var.name} is {what}, got {value}", file=file, entry=entry,
                               fix=f"give an integer between {low} and {high}")]
    return []


FLOAT32_MAX = 3.4028234663852886e38
"""The largest finite Float32 value."""


def _hexadecimal(text: str) -> bool:
    """True if `text` is bytes written as hexadecimal digits, two per byte (a Binary value)."""
    try:
        bytes.fromhex(text)
    except ValueError:
        return False
    return len(text) % 2 == 0 and " " not in text


def _utf8(text: str) -> bool:
    """True if `text` can be encoded as UTF-8: not if it holds lone surrogates, which Python uses
    for bytes of a command line that are not UTF-8 (a String would fail only when set in the FMU)."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True


def _shown(value, limit: int = 40) -> str:
    """repr of `value`, a text cut to `limit` characters so a very long one keeps the error line short."""
    if isinstance(value, str) and len(value) > limit:
        return repr(value[:limit]) + f"... ({len(value)} characters)"
    return repr(value)


def _a(word: str) -> str:
    """The indefinite article for `word` ('an output', 'a parameter')."""
    return "an" if word[:1].lower() in "aeiou" else "a"


def load_system(path, overrides=None, overrides_file=None, *, fmus: FmuResolver) -> System:
    """Load and validate a wiring file; `overrides` {'comp.var': value} take precedence.

    overrides_file names where the overrides came from, for error messages. An .ssp archive
    is read into the same document (aotv_cosim.model.ssp_load) and checked the same way.
    `fmus` gives the .fmu file of each FMU name or source the wiring refers to (`FmuResolver`).
    """
    path = resolved(path, what="wiring file")
    if path.suffix == ".ssp":
        doc, base, _ = read_ssp(path)
        check_document(doc, "wiring", path)
    else:
        doc, base = load_document(path, "wiring"), path.parent
    problems = []
    components = {}
    for name, spec in doc["components"].items():
        entry = f"components.{name}.fmu"
        try:
            found = resolve_fmu(spec["fmu"], base, fmus, file=path, entry=entry)
            info = found if isinstance(found, FmuInfo) else read_fmu(found, file=path, entry=entry)
        except AotvError as exc:
            exc.file = exc.file or path
            exc.entry = exc.entry or entry
            problems.append(exc)
            continue
        components[name] = Component(name, spec["fmu"], info, dict(spec.get("parameters", {})))
    raise_if_any(problems)

    for comp in components.values():
        for var, value in comp.parameters.items():
            entry = f"components.{comp.name}.parameters.{var}"
            problems += _check_known(comp, var, path, entry) or check_value(
                comp.fmu.variables[var], value, file=path, entry=entry, fmu=comp.fmu) or check_range(
                comp.fmu, var, value, file=path, entry=entry)
    problems += _set_values(components, overrides or {}, overrides_file)
    raise_if_any(problems)
    _enumerations_as_integers(components)

    connections = []
    for k, text in enumerate(doc["connections"]):
        entry = f"connections[{k}] '{text}'"
        try:
            conn = parse_connection(text, file=path, entry=entry)
        except InputError as exc:
            problems.append(exc)
            continue
        connections.append(conn)
        problems += _check_connection(conn, components, path, entry)
    raise_if_any(problems)

    system = System(path, components, connections, _unit_warnings(connections, components))
    problems += _check_inputs(system)
    raise_if_any(problems)
    _check_loops(system)
    return system


def with_values(system: System, values: dict, file) -> System:
    """A copy of the loaded `system` with `values` {'comp.var': value} set, checked as
    `load_system` checks its overrides (`file`: where they came from, for error messages); the
    wiring file is not read again."""
    components = {name: replace(comp, parameters=dict(comp.parameters)) for name, comp in system.components.items()}
    raise_if_any(_set_values(components, values, file))
    _enumerations_as_integers(components)
    result = replace(system, components=components, warnings=list(system.warnings))
    raise_if_any(_check_inputs(result))
    return result


def _set_values(components, values, file) -> list:
    """Set `values` {'comp.var': value} on `components`; the problems of those that cannot be set."""
    problems = []
    for signal, value in values.items():
        entry = f"parameters.{signal}"
        comp_name, var = signal.split(".", 1) if "." in signal else (signal, "")
        if comp_name not in components:
            problems.append(_unknown_component(comp_name, components, file, entry))
            continue
        found = _check_known(components[comp_name], var, file, entry)
        problems += found or check_value(components[comp_name].fmu.variables[var], value,
                                         file=file, entry=entry,
                                         fmu=components[comp_name].fmu) or check_range(
            components[comp_name].fmu, var, value, file=file, entry=entry)
        if not found:
            components[comp_name].parameters[var] = value
    return problems


def _enumerations_as_integers(components) -> None:
    """Enumeration items given by name -> their integers."""
    for comp in components.values():
        comp.parameters = {var: enumeration_value(comp.fmu, var, value)
                           if comp.fmu.variables[var].type == "Enumeration" else value
                           for var, value in comp.parameters.items()}


def _unknown_component(name, components, file, entry):
    return InputError(f"unknown component {name!r}", file=file, entry=entry,
                      fix=f"use one of {', '.join(components)}")


def _check_known(comp, var, file, entry):
    if var in comp.fmu.variables:
        return []
    names = list(comp.fmu.variables)
    close = difflib.get_close_matches(var, names, n=3)
    hint = f"did you mean {' or '.join(close)}? " if close else ""
    kinds = [(plural, [v.name for v in comp.fmu.variables.values() if v.causality == causality])
             for causality, plural in (("parameter", "parameters"), ("input", "inputs"), ("output", "outputs"))]
    listed = "; ".join(f"{plural}: {', '.join(found) or 'none'}" for plural, found in kinds)
    others = [v.name for v in comp.fmu.variables.values() if v.causality not in ("parameter", "input", "output")]
    listed += f"; other: {', '.join(others)}" if others else ""
    return [InputError(f"{comp.name} ({Path(comp.fmu_ref).name}) has no variable {var!r}", file=file, entry=entry,
                       fix=f"{hint}its {listed} (`aotv-cosim describe {comp.fmu_ref}` lists them with units)")]


def _check_connection(conn, components, file, entry):
    problems = []
    for comp, var, causality in ((conn.source, conn.output, "output"), (conn.target, conn.input, "input")):
        if comp not in components:
            problems.append(_unknown_component(comp, components, file, entry))
            continue
        known = _check_known(components[comp], var, file, entry)
        if known:
            problems += known
            continue
        actual = components[comp].fmu.variables[var].causality
        if actual != causality:
            side = "source" if causality == "output" else "target"
            problems.append(InputError(f"{comp}.{var} is {_a(actual)} {actual}, the {side} must be an {causality}",
                                       file=file, entry=entry, fix="connect an output to an input"))
    if problems:
        return problems
    out = components[conn.source].fmu.variables[conn.output]
    inp = components[conn.target].fmu.variables[conn.input]
    if conn.as_type is not None:
        if out.type not in ("Integer", "Boolean") or inp.fmi_type not in FLOAT64_CALLS:
            problems.append(InputError(f"cannot convert {out.fmi_type} -> {inp.fmi_type} (as {conn.as_type})",
                                       file=file, entry=entry,
                                       fix="'(as Real)' feeds an Integer or Boolean output to a Real input (FMI 3.0: "
                                           "Float64)"))
        return problems
    if not lossless(out.fmi_type, inp.fmi_type):
        convertible = out.type in ("Integer", "Boolean") and inp.fmi_type in FLOAT64_CALLS
        narrower = out.type == inp.type and out.type in ("Integer", "Real")
        problems.append(InputError(f"type mismatch: {out.fmi_type} -> {inp.fmi_type}", file=file, entry=entry,
                                   fix="connect variables of the same type" + (
                                       ", or write 'source.output -> target.input (as Real)' to convert"
                                       if convertible else "") + (
                                       f", or into a type that holds every {out.fmi_type} value (an integer into a "
                                       "wider one, Float32 into Float64)" if narrower else "")))
    elif out.type == "Enumeration" and (declared_type_name(components[conn.source].fmu, conn.output)
                                        != declared_type_name(components[conn.target].fmu, conn.input)):
        problems.append(InputError(
            f"Enumeration type mismatch: {declared_type_name(components[conn.source].fmu, conn.output)} -> "
            f"{declared_type_name(components[conn.target].fmu, conn.input)}", file=file, entry=entry,
            fix="connect Enumerations of the same declared type"))
    elif out.unit and inp.unit and out.unit != inp.unit:
        problems.append(InputError(f"unit mismatch: {out.unit} -> {inp.unit}", file=file, entry=entry,
                                   fix="connect variables of the same unit (SI at every interface)"))
    return problems


def _unit_warnings(connections, components) -> list:
    """A warning per connection whose output or input declares a unit and the other does not."""
    warnings = []
    for conn in connections:
        out = components[conn.source].fmu.variables[conn.output]
        inp = components[conn.target].fmu.variables[conn.input]
        if bool(out.unit) != bool(inp.unit) and conn.as_type is None:
            side, unit = ("input", inp.unit) if inp.unit else ("output", out.unit)
            warnings.append(f"connection {conn}: only the {side} declares a unit ({unit}); "
                            "check that the other side is in it")
    return warnings


def _check_inputs(system):
    problems = []
    seen: dict = {}
    for k, conn in enumerate(system.connections):
        key = (conn.target, conn.input)
        if key in seen:
            problems.append(InputError(f"{conn.target}.{conn.input} has two sources ({seen[key]} and {conn})",
                                       file=system.path, entry=f"connections[{k}]",
                                       fix="keep one connection per input"))
        seen[key] = str(conn)
    for comp in system.components.values():
        for var in comp.fmu.variables.values():
            if var.causality != "input":
                continue
            connected = (comp.name, var.name) in seen
            valued = var.name in comp.parameters
            entry = f"components.{comp.name}"
            if connected and valued:
                problems.append(InputError(f"input {var.name} is both connected and given a value",
                                           file=system.path, entry=f"{entry}.parameters.{var.name}",
                                           fix="remove the value or the connection"))
            elif not connected and not valued:
                unit = f" in {var.unit}" if var.unit else ""
                problems.append(InputError(f"input {var.name} is not connected and has no value",
                                           file=system.path, entry=entry,
                                           fix=f"connect it or set \"{var.name}\"{unit} under parameters"))
    return problems


def _check_loops(system):
    """Reject a cycle of same-instant dependencies (an algebraic loop) between variables."""
    edges: dict = {}
    for conn in system.connections:
        edges.setdefault(("out", conn.source, conn.output), []).append(("in", conn.target, conn.input))
    for comp in system.components.values():
        for out, deps in comp.fmu.feedthrough.items():
            for inp in deps:
                edges.setdefault(("in", comp.name, inp), []).append(("out", comp.name, out))
    state = {}

    def visit(node, trail):
        state[node] = "open"
        for nxt in edges.get(node, ()):
            if state.get(nxt) == "open":
                cycle = [*trail[trail.index(nxt):], nxt]
                text = " -> ".join(f"{c}.{v}" for kind, c, v in cycle if kind == "out")
                raise InputError(f"algebraic loop of direct feedthrough: {text}", file=system.path,
                                 entry="connections",
                                 fix="break the loop with a component that has no direct feedthrough")
            if nxt not in state:
                visit(nxt, [*trail, nxt])
        state[node] = "done"

    for node in list(edges):
        if node not in state:
            visit(node, [node])
