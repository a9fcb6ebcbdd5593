"""The coupling of a system's FMU instances: the values they exchange and one communication step.

`Coupling` owns the master's value buffer (one ctypes array of float64, `array` its numpy view,
`index` signal -> position, `types` signal -> kind), the calls prepared over it, and what a step
does with them: `advance(t, step, t_new)` steps every component and exchanges values as
`ordering.sweep` says, `extrapolate` sets the delayed inputs to their extrapolation (extrapolated
inputs), `read_all(t)` reads every output, `save`/`restore`/`free` keep and bring back every FMU's
state with the buffer, and `watches` lists the stop conditions and range watches on the buffer.
The fixed-step loop (`master.Master._loop`) and the error-controlled one (`step_doubling.loop`) use
only these.

The calls are the instances' own (`instance.FmuInstance`: `getter`, `setter`, `stepper`), made
once per run over `Slots` of the buffer, whatever the instance is: FMI 2.0 or 3.0 through C, or a
slave called in this interpreter. A component's Float64 (Real) outputs lie side by side in the
buffer and inputs whose sources lie side by side are passed as one piece of it (no copy per step
where the instance can use it: a view for C, a slice for Python); its other values (Float32,
integers, Booleans, Strings, Enumerations) go through one call per FMI type.
"""

import ctypes
from collections.abc import Callable
from typing import cast

import numpy as np

from aotv_cosim.model.ranges import range_watches
from aotv_cosim.model.variable_types import FLOAT64_CALLS
from aotv_cosim.simulation import ordering, watchdog
from aotv_cosim.simulation.instance import NO_SLOTS, Slots


class Saved:
    """Every FMU's state and the buffer at one communication point (`Coupling.save`)."""

    def __init__(self, instances, buffer):
        self.instances = instances
        self.handles = [inst.save_state() for inst in instances]
        self.buffer = buffer


class Layout:
    """Where one component's values lie in the buffer, laid out once before stepping.

    outputs: its Float64 (Real) outputs read, at offset, offset + 1, ...; the last `stale` of
    them are re-read later in each sweep (they feed through from an input set after the
    component stepped), so the read right after its step covers only the others (`fresh_outputs`)
    and those outputs are not computed twice per step."""

    def __init__(self, inst, outputs, offset, stale=0):
        self.inst = inst
        self.name = inst.name
        self.offset = offset
        vrs = [inst.info.variables[o].vr for o in outputs]
        self.outputs = Slots(tuple(vrs), tuple(range(offset, offset + len(vrs))))
        self.fresh_outputs = Slots(self.outputs.vrs[:len(vrs) - stale], self.outputs.positions[:len(vrs) - stale])
        self.float64 = inst.info.call_type(outputs[0]) if outputs else None


class Coupling:
    """The value buffer and the prepared calls of one run (module docstring).

    scenario: the run's Scenario; instances: {name: FmuInstance}, initialized; signals: the
    outputs the master reads besides the connected ones (`master.signals_to_read`); strings: the
    run's `variable_types.Strings` table (String values are numbered in the buffer).
    """

    def __init__(self, scenario, instances: dict, signals: list, strings):
        self.scenario = scenario
        self.instances = instances
        self.strings = strings
        self._build(signals)
        self.advance: Callable = cast(Callable, None)  # None until `start_stepping`
        self.extrapolate: Callable = cast(Callable, None)

    # ---- layout -------------------------------------------------------------------------------
    def _build(self, wanted):
        s = self.scenario
        system = s.system
        self.sources = system.source_of()
        # Connected outputs first, in connection order, so that the inputs a component takes
        # from one source sit side by side in the buffer and are passed without a copy.
        connected = list(dict.fromkeys(f"{c.source}.{c.output}" for c in system.connections))
        signals = connected + [sig for sig in wanted if sig not in connected]
        by_comp = {name: [sig.split(".", 1)[1] for sig in signals if sig.split(".", 1)[0] == name]
                   for name in system.components}
        sweep = self.sweep = ordering.sweep(system, by_comp, jacobi=s.algorithm == "jacobi")
        order = sweep.order
        real = {name: [o for o in by_comp[name] if self._float64(name, o)] for name in order}
        # Outputs re-read after the step go last, so that their re-reads are views of the buffer.
        reread = {(comp, o) for kind, comp, names in self._sweep_actions(sweep) if kind == "get"
                  for o in names}
        stale = {}
        for name in order:
            tail = [o for o in real[name] if (name, o) in reread]
            real[name] = [o for o in real[name] if o not in tail] + tail
            # Gauss-Seidel sets no input from them before their re-read; Jacobi sets every input
            # from the values read right after the steps, so it reads them all there.
            stale[name] = 0 if s.algorithm == "jacobi" else len(tail)
        # Float32, integer, Boolean, Enumeration and String outputs after every Float64 one.
        self.typed = {name: [o for o in by_comp[name] if o not in real[name]] for name in order}
        n_real = sum(len(v) for v in real.values())
        total = n_real + sum(len(v) for v in self.typed.values())
        self.values = (ctypes.c_double * max(total, 1))()
        """The buffer: every output the master reads, as float64 (ctypes array)."""
        # a ctypes array has the buffer protocol, which numpy's frombuffer stubs do not accept
        self.array = np.frombuffer(self.values, dtype=np.float64)[:total]  # type: ignore[call-overload]
        """The buffer as a numpy array (a view)."""
        self.index, layouts, offset = {}, [], 0
        for name in order:
            layout = Layout(self.instances[name], real[name], offset, stale[name])
            for k, out in enumerate(real[name]):
                self.index[f"{name}.{out}"] = offset + k
            offset += len(real[name])
            layouts.append(layout)
        for name in order:
            for out in self.typed[name]:
                self.index[f"{name}.{out}"] = offset
                offset += 1
        self.types = {sig: system.variable(sig).type for sig in self.index}
        self.layouts = layouts
        self.order = order
        self.extrapolated = {name: [i for i in sweep.delayed[name] if self._extrapolable(name, i)]
                             for name in order}
        """{component: its delayed inputs that extrapolated inputs extrapolate}: Float64 inputs
        from Real outputs; the others (converted from an integer or Boolean, Float32) are held."""
        self.start = self._calls(ordering.start_actions(system, by_comp))

    def _float64(self, name, var) -> bool:
        return self.instances[name].info.call_type(var) in FLOAT64_CALLS

    def _extrapolable(self, name, inp) -> bool:
        source = self.scenario.system.variable(".".join(self.sources[(name, inp)]))
        return self._float64(name, inp) and source.type == "Real"

    @staticmethod
    def _sweep_actions(sweep):
        return [a for name in sweep.order for a in sweep.before[name]] + sweep.finish

    def _slots(self, kind, name, names):
        """{call type: Slots} of the variables `names` of component `name`: an input's values at
        its source's position in the buffer, an output's at its own; Float64 (Real) first."""
        info = self.instances[name].info
        groups: dict = {}
        for var in sorted(names):
            where = self.index[".".join(self.sources[(name, var)]) if kind == "set" else f"{name}.{var}"]
            groups.setdefault(info.call_type(var), []).append((info.variables[var].vr, where))
        ordered = sorted(groups, key=lambda t: t not in FLOAT64_CALLS)
        return {t: Slots.of([vr for vr, _ in groups[t]], [p for _, p in groups[t]]) for t in ordered}

    def _bound(self, kind, name, names) -> list:
        """The bound calls (f(t)) that get or set `names` of component `name`, one per FMI type."""
        inst = self.instances[name]
        make = inst.getter if kind == "get" else inst.setter
        return [make(call_type, slots, self.values, self.strings)
                for call_type, slots in self._slots(kind, name, names).items()]

    def _calls(self, actions) -> list:
        """The bound calls of `ordering` actions ((kind, component, names)), in order."""
        return [call for kind, name, names in actions for call in self._bound(kind, name, names)]

    # ---- values -------------------------------------------------------------------------------
    def read_all(self, t: float) -> None:
        """Read every output into the buffer (t: the time, s, for a failure's message)."""
        for call in self._read_calls():
            call(t)

    def _read_calls(self) -> list:
        """The bound calls that read every output: per component its Float64 ones, then the others."""
        calls = []
        for layout in self.layouts:
            if layout.outputs.n:
                calls.append(layout.inst.getter(layout.float64, layout.outputs, self.values, self.strings))
            calls += self._bound("get", layout.name, self.typed[layout.name])
        return calls

    def set_start_inputs(self, t: float) -> None:
        """Set the inputs from the outputs read after initialization (`ordering.start_actions`)."""
        for call in self.start:
            call(t)

    def watches(self) -> list:
        """(buffer index, threshold, direction, condition) of every stop condition and range watch."""
        s = self.scenario
        return [(self.index[c.signal], c.threshold, c.direction, c)
                for c in [*s.stop_conditions, *range_watches(s.system, self.index)]]

    def save(self) -> Saved:
        """Every FMU's state (fmi2GetFMUstate) and a copy of the buffer."""
        return Saved(list(self.instances.values()), self.array.copy())

    def restore(self, saved: Saved, t: float) -> None:
        """Back to `saved` (it stays valid): every FMU's state and the buffer (t, s: for a failure)."""
        for inst, handle in zip(saved.instances, saved.handles):
            inst.restore_state(handle, t)
        self.array[:] = saved.buffer

    def free(self, saved: Saved) -> None:
        """Free the states of `saved`, except on an instance that failed (`FmuInstance.close`)."""
        for inst, handle in zip(saved.instances, saved.handles):
            if not inst.broken:
                inst.free_state(handle)

    def broken(self) -> bool:
        """True if an instance failed (error or fatal): its state can no longer be used."""
        return any(inst.broken for inst in self.instances.values())

    # ---- stepping -------------------------------------------------------------------------------
    def start_stepping(self) -> None:
        """Bind the calls of a step: sets `advance` and `extrapolate` (None with held inputs).

        advance(t, step, t_new): one communication step of every component from t, values
        exchanged as `ordering.sweep` says (Gauss-Seidel) or all after all stepped (Jacobi),
        then the calls that finish the sweep; the buffer then holds the outputs at t_new.
        extrapolate(t, h, h_next, last): see `_end_of_sweep`. The instances bind their calls
        here, so what is put on an instance after the coupling was built (bench/run.py times
        every C call) is what is called."""
        finish, self.extrapolate = self._end_of_sweep()
        self.advance = self._sweeper(finish)

    def _end_of_sweep(self):
        """(finish, extrapolate): what a sweep does after the last component has stepped.

        `finish` are the bound calls that set the inputs not yet set with their sources' values
        at the new communication point and re-read the outputs that feed through from them, in
        the order of `ordering.sweep`. With held inputs (default) `extrapolate` is None. With
        extrapolated inputs it is `extrapolate(t, h, h_next, last)`, which then sets each
        extrapolated input (`extrapolated`) to the mean over the coming step of the line through
        its source's last two values, v + (h_next / 2) (v - v_prev) / h, `last` holding the
        buffer one step (h) ago: the coupling error becomes second order in the step for
        components that hold their inputs over a step. The re-reads are made before, with the
        exact values set; without re-reads, and with every input set there extrapolated, the
        exact values are not set at all.
        """
        finish = self._calls(self.sweep.finish)
        if self.scenario.inputs != "extrapolated":
            return finish, None
        values, lines = self.values, []
        for name in self.order:
            inputs = self.extrapolated[name]
            if not inputs:
                continue
            (call_type, slots), = self._slots("set", name, inputs).items()
            scratch = (ctypes.c_double * slots.n)()  # the extrapolated values, set from here
            set_ = self.instances[name].setter(call_type, Slots(slots.vrs, tuple(range(slots.n))), scratch,
                                               self.strings)
            lines.append((set_, scratch, tuple(enumerate(slots.positions))))

        def extrapolate(t, h, h_next, last):
            c_slope = 0.5 * h_next / h
            for set_, vals, slots in lines:
                for i, j in slots:  # a few values: plain floats cost less than numpy here
                    now = values[j]
                    vals[i] = now + c_slope * (now - last[j])
                set_(t)
        extrapolated = {(name, i) for name, inputs in self.extrapolated.items() for i in inputs}
        exact = any(kind == "get" or any((name, i) not in extrapolated for i in names)
                    for kind, name, names in self.sweep.finish)
        return (finish if exact else []), extrapolate

    def _sweeper(self, finish):
        jacobi = self.scenario.algorithm == "jacobi"
        rollback = self.scenario.step_control is not None
        steps = [self._component_step(layout, jacobi, rollback) for layout in self.layouts]

        def jacobi_sweep(t, step, t_new):
            if type(t) is not float or type(step) is not float:  # the C calls' doubles
                t, step = float(t), float(step)
            for do_step, _read in steps:
                do_step(t, step, t_new)
            for _step, read in steps:
                read(t_new)
            for call in finish:
                call(t_new)

        def gauss_seidel(t, step, t_new):
            if type(t) is not float or type(step) is not float:  # the C calls' doubles
                t, step = float(t), float(step)
            for one, _ in steps:
                one(t, step, t_new)
            for call in finish:
                call(t_new)
        return watchdog.limited(jacobi_sweep if jacobi else gauss_seidel, self.scenario.step_timeout,
                                {name: inst.step_call for name, inst in self.instances.items()})

    def _component_step(self, layout, jacobi, rollback):
        """(step, read) of one component: step(t, h, t_new) makes the calls `before` its step,
        sets its fresh inputs, steps it and (Gauss-Seidel) reads its outputs, then the calls
        `after` (its other outputs); read(t_new) reads its outputs (Jacobi, whose sweep sets
        every input in `finish`). The instance's `stepper` is the step itself when there is
        nothing before or after it."""
        name, inst = layout.name, layout.inst
        after = self._bound("get", name, self.typed[name])
        read_out = [inst.getter(layout.float64, layout.outputs, self.values, self.strings)] if layout.outputs.n else []
        if jacobi:
            reads = read_out + after

            def read(t_new):
                for call in reads:
                    call(t_new)
            return inst.stepper(NO_SLOTS, NO_SLOTS, self.values, rollback), read
        fresh = self._slots("set", name, self.sweep.fresh[name])
        float64 = [t for t in fresh if t in FLOAT64_CALLS]
        core = inst.stepper(fresh.pop(float64[0]) if float64 else NO_SLOTS, layout.fresh_outputs, self.values,
                            rollback)
        before = self._calls(self.sweep.before[name]) + [inst.setter(t, slots, self.values, self.strings)
                                                         for t, slots in fresh.items()]
        if not before and not after:
            return core, None

        def step(t, h, t_new):
            for call in before:
                call(t_new)
            core(t, h, t_new)
            for call in after:
                call(t_new)
        return step, None
