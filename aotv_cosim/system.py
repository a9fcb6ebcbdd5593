"""Wiring file -> validated System: components, FMUs, parameter values, connections, order.

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
import zipfile
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath

from fmpy import read_model_description

from aotv_cosim import fmu_build
from aotv_cosim.documents import check_document, load_document
from aotv_cosim.errors import AotvError, InputError, raise_if_any


@dataclass(frozen=True)
class Variable:
    """One scalar variable of an FMU, as its modelDescription declares it."""

    name: str
    vr: int
    type: str
    causality: str
    variability: str
    unit: str
    start: object
    description: str


@dataclass
class FmuInfo:
    """An FMU file and what its modelDescription says."""

    path: Path
    model_description: object
    variables: dict
    feedthrough: dict
    initial_feedthrough: dict

    @property
    def guid(self):
        return self.model_description.guid

    @property
    def model_identifier(self):
        return self.model_description.coSimulation.modelIdentifier


@dataclass
class Component:
    name: str
    fmu_ref: str
    fmu: FmuInfo
    parameters: dict = field(default_factory=dict)


@dataclass(frozen=True)
class Connection:
    source: str
    output: str
    target: str
    input: str

    def __str__(self):
        return f"{self.source}.{self.output} -> {self.target}.{self.input}"


@dataclass
class System:
    """A validated wiring: components in file order and their connections."""

    path: Path
    components: dict
    connections: list

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

    def gauss_seidel_order(self):
        """Component order for Gauss-Seidel stepping.

        A connection is 'immediate' when its target input feeds through (same instant) to an
        output of the target that is itself connected onward: its source must be stepped first
        so that algebraic chains see consistent values. All other connections (into states, or
        into outputs only recorded) are delayed by one step and break cycles. Components are
        sorted topologically over the immediate connections, ties kept in file order.
        """
        connected = {(c.source, c.output) for c in self.connections}
        after = {name: set() for name in self.components}
        for c in self.connections:
            fmu = self.components[c.target].fmu
            if any(c.input in deps and (c.target, out) in connected
                   for out, deps in fmu.feedthrough.items()):
                after[c.target].add(c.source)
        order, placed = [], set()
        while len(order) < len(after):
            ready = [n for n in after if n not in placed and after[n] <= placed]
            if not ready:
                raise InputError("components depend on each other at the same instant",
                                 file=self.path, entry="connections",
                                 fix="break the feedthrough cycle")
            order.append(ready[0])
            placed.add(ready[0])
        return order


def resolve_fmu(ref: str, base: Path, *, file=None, entry=None) -> Path:
    """An FMU reference of a wiring file: a path ending in .fmu (relative to base) or a name in fmus_src."""
    if ref.endswith(".fmu"):
        return (base / ref).resolve()
    names = fmu_build.available_fmus()
    if ref not in names:
        close = difflib.get_close_matches(ref, names, n=3)
        hint = f"did you mean {' or '.join(close)}? " if close else ""
        raise InputError(f"no FMU named {ref!r} in this package", file=file, entry=entry,
                         fix=f"{hint}give a path to a .fmu file (relative to the wiring file) "
                             f"or one of {', '.join(names)}")
    return fmu_build.ensure_fmu(ref)


def check_archive(path: Path, *, file=None, entry=None) -> None:
    """Refuse an FMU or SSP archive whose member names are absolute or climb out with '..'.

    The error names `file` and `entry` (the document that refers to the archive) when given,
    else the archive itself. A file that is not a zip archive raises zipfile.BadZipFile.
    """
    with zipfile.ZipFile(path) as archive:
        for name in archive.namelist():
            pure = PurePosixPath(name.replace("\\", "/"))
            drive = bool(pure.parts) and ":" in pure.parts[0]
            if pure.is_absolute() or ".." in pure.parts or drive:
                raise InputError(f"member {name!r} of {Path(path).name} escapes the extraction folder",
                                 file=file or path, entry=entry,
                                 fix="rebuild the archive with relative member names")


def read_fmu(path: Path, *, file, entry) -> FmuInfo:
    """Read an FMU's modelDescription into an FmuInfo; InputError if missing or corrupt."""
    if not path.is_file():
        raise InputError(f"FMU file not found: {path}", file=file, entry=entry,
                         fix="correct the path (relative to the wiring file) or build the FMU")
    try:
        check_archive(path, file=file, entry=entry)
        md = read_model_description(str(path))
    except InputError:
        raise
    except Exception as exc:  # fmpy raises many kinds for a corrupt archive or XML
        raise InputError(f"cannot read FMU {path.name}: {exc}", file=file, entry=entry,
                         fix="give a valid FMI 2.0 co-simulation FMU")
    if md.fmiVersion != "2.0" or md.coSimulation is None:
        raise InputError(f"{path.name} is not an FMI 2.0 co-simulation FMU", file=file, entry=entry,
                         fix="export the FMU for FMI 2.0 co-simulation")
    variables = {v.name: Variable(v.name, v.valueReference, v.type, v.causality, v.variability,
                                  v.unit or (v.declaredType.unit if v.declaredType else None) or "",
                                  v.start, v.description or "")
                 for v in md.modelVariables}
    inputs = [v.name for v in md.modelVariables if v.causality == "input"]
    feedthrough = _dependencies(md.outputs, inputs)
    initial = _dependencies(md.initialUnknowns, inputs)
    return FmuInfo(path, md, variables, feedthrough, {**feedthrough, **initial})


def _dependencies(unknowns, inputs):
    """{output: set of inputs it depends on}; no dependencies attribute means all inputs."""
    deps = {}
    for u in unknowns:
        if u.dependencies is None:
            deps[u.variable.name] = set(inputs)
        else:
            deps[u.variable.name] = {d.name for d in u.dependencies if d.causality == "input"}
    return deps


def parse_connection(text: str, *, file=None, entry=None) -> Connection:
    """'source.output -> target.input' (as the schema checked it) -> Connection."""
    sides = [s.strip() for s in text.split("->")]
    if len(sides) != 2 or not all("." in side for side in sides):
        raise InputError(f"cannot read connection {text!r}", file=file, entry=entry,
                         fix="write one 'source.output -> target.input' per entry")
    source, output = sides[0].split(".", 1)
    target, inp = sides[1].split(".", 1)
    return Connection(source, output, target, inp)


def check_value(var: Variable, value, *, file, entry):
    """Problems with giving `value` to variable `var` (type, finiteness, causality)."""
    if var.causality not in ("parameter", "input"):
        return [InputError(f"{var.name} is {_a(var.causality)} {var.causality}, it cannot be given a value",
                           file=file, entry=entry, fix="set a parameter or an unconnected input")]
    ok = {"Real": isinstance(value, (int, float)) and not isinstance(value, bool),
          "Integer": isinstance(value, int) and not isinstance(value, bool),
          "Boolean": isinstance(value, bool),
          "String": isinstance(value, str)}.get(var.type, False)
    if not ok:
        return [InputError(f"{var.name} is {var.type}, got {value!r}", file=file, entry=entry,
                           fix=f"give {_a(var.type)} {var.type} value" + (f" in {var.unit}" if var.unit else ""))]
    if var.type == "Real" and not math.isfinite(value):
        return [InputError(f"{var.name} must be finite, got {value!r}", file=file, entry=entry,
                           fix="give a finite number")]
    if var.type == "Integer" and not -2**31 <= value < 2**31:
        return [InputError(f"{var.name} is a 32-bit Integer, got {value}", file=file, entry=entry,
                           fix="give an integer between -2147483648 and 2147483647")]
    return []


def _a(word: str) -> str:
    """The indefinite article for `word` ('an output', 'a parameter')."""
    return "an" if word[:1].lower() in "aeiou" else "a"


def load_system(path, overrides=None, overrides_file=None) -> System:
    """Load and validate a wiring file; `overrides` {'comp.var': value} take precedence.

    overrides_file names where the overrides came from, for error messages. An .ssp archive
    is read into the same document (aotv_cosim.ssp.load) and checked the same way.
    """
    path = Path(path).resolve()
    if path.suffix == ".ssp":
        from aotv_cosim.ssp.load import read_ssp

        doc, base, _ = read_ssp(path)
        check_document(doc, "wiring", path)
    else:
        doc, base = load_document(path, "wiring"), path.parent
    problems = []
    components = {}
    for name, spec in doc["components"].items():
        entry = f"components.{name}.fmu"
        try:
            fmu_path = resolve_fmu(spec["fmu"], base, file=path, entry=entry)
            info = read_fmu(fmu_path, file=path, entry=entry)
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
                comp.fmu.variables[var], value, file=path, entry=entry)
    for signal, value in (overrides or {}).items():
        entry = f"parameters.{signal}"
        comp_name, var = signal.split(".", 1) if "." in signal else (signal, "")
        if comp_name not in components:
            problems.append(_unknown_component(comp_name, components, overrides_file, entry))
            continue
        found = _check_known(components[comp_name], var, overrides_file, entry)
        problems += found or check_value(components[comp_name].fmu.variables[var], value,
                                         file=overrides_file, entry=entry)
        if not found:
            components[comp_name].parameters[var] = value

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

    system = System(path, components, connections)
    problems += _check_inputs(system)
    raise_if_any(problems)
    _check_loops(system)
    return system


def _unknown_component(name, components, file, entry):
    return InputError(f"unknown component {name!r}", file=file, entry=entry,
                      fix=f"use one of {', '.join(components)}")


def _check_known(comp, var, file, entry):
    if var in comp.fmu.variables:
        return []
    names = list(comp.fmu.variables)
    close = difflib.get_close_matches(var, names, n=3)
    hint = f"did you mean {' or '.join(close)}? " if close else ""
    return [InputError(f"{comp.name} ({Path(comp.fmu_ref).name}) has no variable {var!r}", file=file, entry=entry,
                       fix=f"{hint}its variables are {', '.join(names)}")]


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
    if out.type != inp.type:
        problems.append(InputError(f"type mismatch: {out.type} -> {inp.type}", file=file, entry=entry,
                                   fix="connect variables of the same type"))
    elif out.unit and inp.unit and out.unit != inp.unit:
        problems.append(InputError(f"unit mismatch: {out.unit} -> {inp.unit}", file=file, entry=entry,
                                   fix="connect variables of the same unit (SI at every interface)"))
    return problems


def _check_inputs(system):
    problems = []
    seen = {}
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
    edges = {}
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
                cycle = trail[trail.index(nxt):] + [nxt]
                text = " -> ".join(f"{c}.{v}" for kind, c, v in cycle if kind == "out")
                raise InputError(f"algebraic loop of direct feedthrough: {text}", file=system.path,
                                 entry="connections",
                                 fix="break the loop with a component that has no direct feedthrough")
            if nxt not in state:
                visit(nxt, trail + [nxt])
        state[node] = "done"

    for node in list(edges):
        if node not in state:
            visit(node, [node])
