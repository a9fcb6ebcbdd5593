"""Gauss-Seidel and Jacobi orderings of a System: which component steps when, and which values
are set and read around each step.

A connection whose target input feeds through (same instant) to a connected output of the target
is 'immediate': its source steps first. Values then propagate in a topological order of
variables (connections plus each FMU's declared output -> input feedthrough): `sweep` turns
that into the calls of one communication step, `start_actions` into those that make the values
consistent after initialization. The master (`master.Master._build_plans`) binds them to FMI
calls once per run.
"""

from dataclasses import dataclass

from aotv_cosim.errors import InputError

def gauss_seidel_order(system):
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
    sources = system.source_of()
    connected = {(c.source, c.output) for c in system.connections}
    steps = {}

    def stepped_before(comp, out):
        """Components whose step `comp.out` depends on at the same instant."""
        if (comp, out) not in steps:
            deps = {comp}
            for inp in system.connected_feedthrough(comp, out):
                deps |= stepped_before(*sources[(comp, inp)])
            steps[(comp, out)] = deps
        return steps[(comp, out)]

    after: dict[str, set[str]] = {name: set() for name in system.components}
    for c in system.connections:
        fmu = system.components[c.target].fmu
        immediate = any(c.input in deps and (c.target, out) in connected
                        for out, deps in fmu.feedthrough.items())
        if immediate and c.target not in stepped_before(c.source, c.output):
            after[c.target].add(c.source)
    order: list[str] = []
    placed: set[str] = set()
    while len(order) < len(after):
        ready = [n for n in after if n not in placed and after[n] <= placed]
        name = ready[0] if ready else next(n for n in after if n not in placed)
        order.append(name)
        placed.add(name)
    return order

def sweep(system, read, jacobi=False):
    """The calls of one communication step, by variable name (a `Sweep`).

    read: {component: outputs the master reads}, every connected output among them.
    Gauss-Seidel: components step in `gauss_seidel_order`. An input is fresh (set just
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
    order = gauss_seidel_order(system)
    flow = _Flow(system, read)
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

def start_actions(system, read):
    """The calls that make every value consistent after initialization, all outputs read.

    Every component counts as stepped with no input set; the values then propagate in
    topological order of variables as at the end of a sweep.
    """
    flow = _Flow(system, read)
    order = list(system.components)
    for name in order:
        flow.stepped.add(name)
        flow.stale |= {(name, o) for o in read[name] if system.connected_feedthrough(name, o)}
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
