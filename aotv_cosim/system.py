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
from aotv_cosim.ranges import check_range


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

    def connected_feedthrough(self, comp, output):
        """The connected inputs of `comp` that `output` depends on at the same instant."""
        deps = self.components[comp].fmu.feedthrough.get(output, ())
        return {i for i in deps if any(c.target == comp and c.input == i for c in self.connections)}

    def gauss_seidel_order(self):
        """Component order for Gauss-Seidel stepping.

        A connection is 'immediate' when its target input feeds through (same instant) to an
        output of the target that is itself connected onward: its source is stepped first so
        that the chain can be fresh. Such a constraint is dropped when the source output itself
        depends at the same instant on an output of the target (vehicle.rho from atmosphere.rho
        from vehicle.h): that input can never be set before its component steps, whatever the
        order. Components are sorted topologically over the remaining immediate connections,
        ties kept in file order; a cycle left (components feeding each other through different
        variables, no loop at variable level) is broken at its first component in file order.
        Any order is consistent: `sweep` only makes an input fresh once its source is final.
        """
        sources = self.source_of()
        connected = {(c.source, c.output) for c in self.connections}
        steps = {}

        def stepped_before(comp, out):
            """Components whose step `comp.out` depends on at the same instant."""
            if (comp, out) not in steps:
                deps = {comp}
                for inp in self.connected_feedthrough(comp, out):
                    deps |= stepped_before(*sources[(comp, inp)])
                steps[(comp, out)] = deps
            return steps[(comp, out)]

        after = {name: set() for name in self.components}
        for c in self.connections:
            fmu = self.components[c.target].fmu
            immediate = any(c.input in deps and (c.target, out) in connected
                            for out, deps in fmu.feedthrough.items())
            if immediate and c.target not in stepped_before(c.source, c.output):
                after[c.target].add(c.source)
        order, placed = [], set()
        while len(order) < len(after):
            ready = [n for n in after if n not in placed and after[n] <= placed]
            name = ready[0] if ready else next(n for n in after if n not in placed)
            order.append(name)
            placed.add(name)
        return order

    def sweep(self, read, jacobi=False):
        """The calls of one communication step, by variable name (a `Sweep`).

        read: {component: outputs the master reads}, every connected output among them.
        Gauss-Seidel: components step in `gauss_seidel_order()`. An input is fresh (set just
        before its component steps) when its source output can be made final first: its
        component has stepped and every connected input it feeds through from holds its value
        at the new point (set, with the outputs re-read, in `before`). Other inputs are delayed:
        set once their source is final, after their component stepped. After a component steps,
        its outputs that feed through from an input not yet set are stale; they are re-read once
        those inputs are set. So values propagate in a topological order of variables
        (connections plus each FMU's declared output->input feedthrough) and a chain
        vehicle.rho -> vehicle.drag_acc -> guidance.drag sees the drag from the new density.
        Jacobi: no input is fresh; after all steps every input is set, then every output with
        connected feedthrough is re-read once (OSP libcosim's scheme).
        """
        order = self.gauss_seidel_order()
        flow = _Flow(self, read)
        if jacobi:
            for name in order:
                flow.step(name, [])
            return Sweep(order, {n: [] for n in order}, {n: [] for n in order},
                         flow.jacobi_finish(order), flow.delayed(order, {}))
        fresh, before = {}, {}
        for name in order:
            fresh[name] = [i for i in flow.inputs[name] if flow.can_finalize(*flow.sources[(name, i)])]
            before[name] = flow.settle({flow.sources[(name, i)] for i in fresh[name]}, order)
            flow.step(name, fresh[name])
        return Sweep(order, fresh, before, flow.settle_all(order), flow.delayed(order, fresh))

    def start_actions(self, read):
        """The calls that make every value consistent after initialization, all outputs read.

        Every component counts as stepped with no input set; the values then propagate in
        topological order of variables as at the end of a sweep.
        """
        flow = _Flow(self, read)
        order = list(self.components)
        for name in order:
            flow.stepped.add(name)
            flow.stale |= {(name, o) for o in read[name] if self.connected_feedthrough(name, o)}
        return flow.settle_all(order)


@dataclass
class Sweep:
    """One communication step as calls: actions are ("set", comp, inputs) or ("get", comp, outputs).

    order: components in stepping order; fresh: {comp: inputs set just before it steps};
    before: {comp: actions run before that}; finish: actions after the last step; delayed:
    {comp: connected inputs that are not fresh}.
    """

    order: list
    fresh: dict
    before: dict
    finish: list
    delayed: dict


class _Flow:
    """Which values are final at the new communication point while a sweep is built."""

    def __init__(self, system, read):
        self.system = system
        self.read = read
        self.sources = system.source_of()
        self.inputs = {n: [i for (t, i) in self.sources if t == n] for n in system.components}
        self.stepped, self.set, self.stale = set(), set(), set()

    def step(self, name, fresh):
        """`name` steps with `fresh` set; its outputs feeding through from unset inputs are stale."""
        self.set |= {(name, i) for i in fresh}
        self.stepped.add(name)
        self.stale |= {(name, o) for o in self.read[name]
                       if any((name, i) not in self.set for i in self.system.connected_feedthrough(name, o))}

    def can_finalize(self, comp, out):
        return comp in self.stepped and all(
            (comp, i) in self.set or self.can_finalize(*self.sources[(comp, i)])
            for i in self.system.connected_feedthrough(comp, out))

    def settle(self, outputs, order):
        """Actions making `outputs` final: their unset inputs set and they re-read, in waves."""
        inputs, needed, todo = set(), set(), [o for o in outputs if o in self.stale]
        while todo:
            comp, out = todo.pop()
            if (comp, out) in needed:
                continue
            needed.add((comp, out))
            for i in self.system.connected_feedthrough(comp, out):
                if (comp, i) not in self.set:
                    inputs.add((comp, i))
                    if self.sources[(comp, i)] in self.stale:
                        todo.append(self.sources[(comp, i)])
        return self._waves(inputs, needed, order)

    def settle_all(self, order):
        """Actions making every value final: every input not yet set, every stale output."""
        inputs = {(n, i) for n in order for i in self.inputs[n] if (n, i) not in self.set}
        return self._waves(inputs, set(self.stale), order)

    def _waves(self, inputs, outputs, order):
        actions = []
        while inputs or outputs:
            ready = {i for i in inputs if self.sources[i] not in self.stale}
            actions += _grouped("set", ready, order)
            self.set |= ready
            inputs -= ready
            final = {o for o in outputs
                     if all((o[0], i) in self.set for i in self.system.connected_feedthrough(*o))}
            actions += _grouped("get", final, order)
            self.stale -= final
            outputs -= final
            if not ready and not final:
                raise InputError("outputs depend on each other at the same instant",
                                 file=self.system.path, entry="connections",
                                 fix="break the feedthrough cycle")
        return actions

    def jacobi_finish(self, order):
        inputs = {(n, i) for n in order for i in self.inputs[n]}
        stale = set(self.stale)
        self.set |= inputs
        self.stale.clear()
        return _grouped("set", inputs, order) + _grouped("get", stale, order)

    def delayed(self, order, fresh):
        return {n: [i for i in self.inputs[n] if i not in fresh.get(n, ())] for n in order}


def _grouped(kind, pairs, order):
    """One action per component, in `order`, over the (component, name) pairs."""
    return [(kind, n, sorted(name for c, name in pairs if c == n))
            for n in order if any(c == n for c, _ in pairs)]


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
                comp.fmu.variables[var], value, file=path, entry=entry) or check_range(
                comp.fmu, var, value, file=path, entry=entry)
    for signal, value in (overrides or {}).items():
        entry = f"parameters.{signal}"
        comp_name, var = signal.split(".", 1) if "." in signal else (signal, "")
        if comp_name not in components:
            problems.append(_unknown_component(comp_name, components, overrides_file, entry))
            continue
        found = _check_known(components[comp_name], var, overrides_file, entry)
        problems += found or check_value(components[comp_name].fmu.variables[var], value,
                                         file=overrides_file, entry=entry) or check_range(
            components[comp_name].fmu, var, value, file=overrides_file, entry=entry)
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
