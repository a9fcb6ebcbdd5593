"""The coupling of a system's FMU instances: the values they exchange and one communication step.

`Coupling` owns the master's value buffer (one ctypes array of float64, `array` its numpy view,
`index` signal -> position, `types` signal -> FMI type), the FMI calls prepared over it
(`fmi_calls`), and what a step does with them: `advance(t, step, t_new)` steps every component
and exchanges values as `ordering.sweep` says, `extrapolate` sets the delayed inputs to their
extrapolation (extrapolated inputs), `read_all(t)` reads every output, `save`/`restore`/`free`
keep and bring back every FMU's state with the buffer, and `watches` lists the stop conditions
and range watches on the buffer. The fixed-step loop (`master.Master._loop`) and the
error-controlled one (`step_doubling.loop`) use only these.

Outputs are views into the buffer and inputs whose sources lie side by side in it are passed as
views of it (no copy per step). A component whose instance is a `direct_instance.DirectInstance`
(a pythonfmu slave called in this interpreter) is stepped with plain Python floats and lists
instead: its fresh inputs are a slice of the buffer, its outputs are stored into a slice of it.
"""

import ctypes

import numpy as np

from aotv_cosim.simulation import ordering, watchdog
from aotv_cosim.simulation.fmi_calls import Call, Plan, bind, calls_by_type, run_bound
from aotv_cosim.model.ranges import range_watches


class Saved:
    """Every FMU's state and the buffer at one communication point (`Coupling.save`)."""

    def __init__(self, instances, buffer):
        self.instances = instances
        self.handles = [inst.save_state() for inst in instances]
        self.buffer = buffer


class Coupling:
    """The value buffer and the prepared FMI calls of one run (module docstring).

    scenario: the run's Scenario; instances: {name: FmuInstance or DirectInstance}, initialized;
    signals: the outputs the master reads besides the connected ones (`master.signals_to_read`);
    strings: the run's `variable_types.Strings` table (String values are numbered in the buffer).
    """

    def __init__(self, scenario, instances: dict, signals: list, strings):
        self.scenario = scenario
        self.instances = instances
        self.strings = strings
        self.converted = False
        """True when a delayed Real input takes a converted Integer or Boolean output (held, not
        extrapolated: `_end_of_sweep`)."""
        self._build(signals)
        self.advance = self.extrapolate = None

    # ---- plans ------------------------------------------------------------------------------
    def _build(self, wanted):
        s = self.scenario
        system = s.system
        sources = system.source_of()
        # Connected outputs first, in connection order, so that the inputs a component takes
        # from one source sit side by side in the buffer and are passed without a copy.
        connected = list(dict.fromkeys(f"{c.source}.{c.output}" for c in system.connections))
        signals = connected + [sig for sig in wanted if sig not in connected]
        by_comp = {name: [sig.split(".", 1)[1] for sig in signals if sig.split(".", 1)[0] == name]
                   for name in system.components}
        sweep = ordering.sweep(system, by_comp, jacobi=s.algorithm == "jacobi")
        order = sweep.order
        real = {name: [o for o in by_comp[name] if system.components[name].fmu.variables[o].type == "Real"]
                for name in order}
        # Outputs re-read after the step go last, so that their re-reads are views of the buffer.
        reread = {(comp, o) for _, comp, names in self._sweep_actions(sweep) if _ == "get"
                  for o in names}
        stale = {}
        for name in order:
            tail = [o for o in real[name] if (name, o) in reread]
            real[name] = [o for o in real[name] if o not in tail] + tail
            # Gauss-Seidel sets no input from them before their re-read; Jacobi sets every input
            # from the values read right after the steps, so it reads them all there.
            stale[name] = 0 if s.algorithm == "jacobi" else len(tail)
        # Integer, Boolean, Enumeration and String outputs after every Real one (`variable_types`).
        typed = {name: [o for o in by_comp[name] if o not in real[name]] for name in order}
        n_real = sum(len(v) for v in real.values())
        total = n_real + sum(len(v) for v in typed.values())
        self.values = (ctypes.c_double * max(total, 1))()
        """The buffer: every output the master reads, as float64 (ctypes array)."""
        self.array = np.frombuffer(self.values, dtype=np.float64)[:total]
        """The buffer as a numpy array (a view)."""
        self.index, plans, offset = {}, [], 0
        for name in order:
            plan = Plan(self.instances[name], real[name], self.values, offset, stale[name])
            for k, out in enumerate(real[name]):
                self.index[f"{name}.{out}"] = offset + k
            offset += plan.n_out
            plans.append(plan)
        for name in order:
            for out in typed[name]:
                self.index[f"{name}.{out}"] = offset
                offset += 1
        self.types = {sig: system.variable(sig).type for sig in self.index}

        def call(kind, name, names, alias=True):
            where = [self.index[".".join(sources[(name, v)]) if kind == "set" else f"{name}.{v}"]
                     for v in names]
            return calls_by_type(self.instances[name], kind, names, where, self.values, self.strings,
                                 alias)

        def calls(actions):
            return [(kind, self.instances[name], made) for kind, name, names in actions
                    for made in call(kind, name, names) if made.n]

        for plan in plans:
            name = plan.inst.name
            fresh, *typed_fresh = call("set", name, sweep.fresh[name])
            plan.fresh = fresh
            plan.before = calls(sweep.before[name]) + [("set", plan.inst, c) for c in typed_fresh]
            plan.after = [("get", plan.inst, c) for c in call("get", name, typed[name])[1:]]
            # Only Real inputs from Real outputs are extrapolated; converted ones are held.
            held = [i for i in sweep.delayed[name] if system.variable(".".join(sources[(name, i)])).type == "Real"]
            plan.delayed = call("set", name, held, alias=False)[0]
            self.converted |= any(plan.inst.info.variables[i].type == "Real" and
                                  system.variable(".".join(sources[(name, i)])).type != "Real"
                                  for i in sweep.delayed[name])
        self.finish = calls(sweep.finish)
        self.start = calls(ordering.start_actions(system, by_comp))
        self.plans = plans
        self.order = order

    @staticmethod
    def _sweep_actions(sweep):
        return [a for name in sweep.order for a in sweep.before[name]] + sweep.finish

    # ---- values -------------------------------------------------------------------------------
    def read_all(self, t: float) -> None:
        """Read every output into the buffer (t: the time, s, for a failure's message)."""
        for p in self.plans:
            if p.n_out and p.inst.raw_get_real(p.inst.component, p.out_vrs, p.out_size, p.out_vals) > 1:
                raise p.inst.failure("fmi2GetReal", t)
            if p.after:
                run_bound(bind(p.after), self.values, t)

    def set_start_inputs(self, t: float) -> None:
        """Set the inputs from the outputs read after initialization (`ordering.start_actions`)."""
        run_bound(bind(self.start), self.values, t)

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
        extrapolate(t, h, h_next, last): see `_end_of_sweep`. The C entry points are looked up
        here, so a wrapper put on an instance after the plans were built (bench/run.py times
        every call) is the one called."""
        finish, self.extrapolate = self._end_of_sweep()
        self.advance = self._sweeper(finish)

    def _end_of_sweep(self):
        """(finish, extrapolate): what a sweep does after the last component has stepped.

        `finish` are the bound calls that set the inputs not yet set with their sources' values
        at the new communication point and re-read the outputs that feed through from them, in
        the order of `ordering.sweep`. With held inputs (default) `extrapolate` is None. With
        extrapolated inputs it is `extrapolate(t, h, h_next, last)`, which then sets each delayed
        input to the mean over the coming step of the line through its source's last two
        values, v + (h_next / 2) (v - v_prev) / h, `last` holding the buffer one step (h) ago:
        the coupling error becomes second order in the step for components that hold their
        inputs over a step. The re-reads are made before, with the exact values set; without
        re-reads the exact values are not set at all.
        """
        finish = _calls(self.finish, self.values)
        if self.scenario.inputs != "extrapolated":
            return finish, None
        values = self.values
        lines = [(p.inst, getattr(p.inst, "direct", False), p.inst.component, p.inst.raw_set_real,
                  p.delayed.vrs, list(p.delayed.vrs), p.delayed.size, p.delayed.vals,
                  tuple(enumerate(p.delayed.positions)))
                 for p in self.plans if p.delayed.n]

        def extrapolate(t, h, h_next, last):
            c_slope = 0.5 * h_next / h
            for inst, direct, c, set_, vrs, vr_list, size, vals, slots in lines:
                if direct:  # the floats a C array would hold
                    inst.set_reals(vr_list, [float(values[j] + c_slope * (values[j] - last[j]))
                                             for _, j in slots], t)
                    continue
                for i, j in slots:  # a few values: plain floats cost less than numpy here
                    now = values[j]
                    vals[i] = now + c_slope * (now - last[j])
                if set_(c, vrs, size, vals) > 1:
                    raise inst.failure("fmi2SetReal", t)
        exact = any(kind == "get" or not isinstance(call, Call) for kind, _, call in self.finish) or self.converted
        return (finish if exact else []), extrapolate

    def _sweeper(self, finish):
        jacobi = self.scenario.algorithm == "jacobi"
        steps = [(_direct_step if getattr(p.inst, "direct", False) else _c_step)(p, self.values, jacobi)
                 for p in self.plans]

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
        return watchdog.limited(jacobi_sweep if jacobi else gauss_seidel, self.scenario.step_timeout)


def _c_step(p, values, jacobi):
    """(step, read) of plan `p` through the C entry points: step(t, h, t_new) sets its fresh
    inputs, steps it and (Gauss-Seidel) reads its outputs; read(t_new) reads them (Jacobi)."""
    inst, c, do_step, get, set_ = p.inst, p.inst.component, p.inst.raw_do_step, p.inst.raw_get_real, \
        p.inst.raw_set_real
    ovrs, ovals, n_out = p.out_vrs, p.out_vals, p.n_fresh_out
    osize = p.out_size if jacobi else p.fresh_out_size
    fvrs, fvals, pairs, nf, fsize = p.fresh.vrs, p.fresh.vals, p.fresh.pairs, p.fresh.n, p.fresh.size
    before, after = _calls(p.before, values), _calls(p.after, values)
    now, length, new_step = ctypes.c_double(), ctypes.c_double(), ctypes.c_int(1)

    def read(t_new):
        if n_out and get(c, ovrs, osize, ovals) > 1:
            raise inst.failure("fmi2GetReal", t_new)
        for call in after:
            call(t_new)

    def step(t, h, t_new):
        now.value, length.value = t, h
        if not jacobi:
            for call in before:
                call(t_new)
            if nf:
                for i, j in pairs:
                    fvals[i] = values[j]
                if set_(c, fvrs, fsize, fvals) > 1:
                    raise inst.failure("fmi2SetReal", t)
        status = do_step(c, now, length, new_step)
        if status > 1:
            raise inst.refused_step(t, status)
        if jacobi:
            return
        if n_out and get(c, ovrs, osize, ovals) > 1:  # `read`, inlined
            raise inst.failure("fmi2GetReal", t_new)
        for call in after:
            call(t_new)
    return step, read


def _direct_step(p, values, jacobi):
    """`_c_step` for a `DirectInstance`: the same calls with Python lists of floats, the slave's
    methods called here (`DirectInstance.step`, `get_reals`, `set_reals` inlined)."""
    inst = p.inst
    n_out = p.n_out if jacobi else p.n_fresh_out
    first, end = p.offset, p.offset + n_out
    ovrs = list(p.out_vrs)[:n_out]
    fvrs, nf = list(p.fresh.vrs)[:p.fresh.n], p.fresh.n
    positions = tuple(p.fresh.positions)
    lo = positions[0] if positions else 0
    hi = lo + nf
    aliased = not p.fresh.pairs  # consecutive buffer positions: one slice of the buffer
    before, after = _calls(p.before, values), _calls(p.after, values)
    slave_set, slave_step, slave_get = inst.set_real_method, inst.step_method, inst.get_real_method
    queue, drain, stepped, reals, failed = inst.log_queue, inst.drain_log, inst.stepped, inst.reals, inst.failed

    def read(t_new):
        if n_out:
            try:
                out = slave_get(ovrs)
                try:
                    values[first:end] = out  # a sequence of n_out numbers, as the slaves give
                except Exception:  # another length or kind: what the C wrapper makes of it
                    values[first:end] = reals(out, n_out)
            except BaseException as exc:
                raise failed("[getReal]", "fmi2GetReal", exc, t_new) from None
            if queue:
                drain()
        for call in after:
            call(t_new)

    def step(t, h, t_new):
        if not jacobi:
            if before:
                for call in before:
                    call(t_new)
            if nf:
                try:
                    slave_set(fvrs, values[lo:hi] if aliased else [values[j] for j in positions])
                except BaseException as exc:
                    raise failed("[setReal]", "fmi2SetReal", exc, t) from None
                if queue:
                    drain()
        try:
            result = slave_step(t, h)
        except BaseException as exc:
            raise inst.refused_step(t, inst.fatal("[doStep]", exc)) from None
        if result is not True or queue:  # True, no log: fmi2OK (`DirectInstance.stepped`)
            status = stepped(result, t, h)
            if status:
                raise inst.refused_step(t, status)
        if jacobi:
            return
        if n_out:  # `read`, inlined: one Python call fewer per component and step
            try:
                out = slave_get(ovrs)
                try:
                    values[first:end] = out  # a sequence of n_out numbers, as the slaves give
                except Exception:  # another length or kind: what the C wrapper makes of it
                    values[first:end] = reals(out, n_out)
            except BaseException as exc:
                raise failed("[getReal]", "fmi2GetReal", exc, t_new) from None
            if queue:
                drain()
        if after:
            for call in after:
                call(t_new)
    return step, read


def _calls(actions, values) -> list:
    """Functions f(t) making the prepared calls `actions` ((kind, instance, Call or TypedCall),
    `fmi_calls`) in order, t the time for a failure's message: the Real ones of a
    `DirectInstance` with Python lists (`_direct_call`), runs of the others bound together."""
    made, pending = [], []
    for action in actions + [None]:
        direct = action is not None and getattr(action[1], "direct", False) and isinstance(action[2], Call)
        if pending and (action is None or direct):
            bound = bind(pending)
            made.append(lambda t, bound=bound: run_bound(bound, values, t))
            pending = []
        if direct:
            made.append(_direct_call(action[0] == "get", action[1], action[2], values))
        elif action is not None:
            pending.append(action)
    return made


def _direct_call(is_get, inst, call, values):
    """f(t): the fmi2GetReal or fmi2SetReal of `call` on DirectInstance `inst`, its values taken
    from or stored into the buffer `values` (one slice when their positions are consecutive)."""
    vrs, n, positions = list(call.vrs)[:call.n], call.n, tuple(call.positions)
    lo = positions[0]
    aliased = positions == tuple(range(lo, lo + n))
    if is_get and aliased:
        slave_get, queue, drain, reals, failed = (inst.get_real_method, inst.log_queue, inst.drain_log,
                                                  inst.reals, inst.failed)

        def get_slice(t):
            try:
                out = slave_get(vrs)
                values[lo:lo + n] = out if type(out) is list and len(out) == n else reals(out, n)
            except BaseException as exc:
                raise failed("[getReal]", "fmi2GetReal", exc, t) from None
            if queue:
                drain()
        return get_slice
    if is_get:
        def get_scattered(t):
            for j, value in zip(positions, inst.get_reals(vrs, n, t)):
                values[j] = value
        return get_scattered
    slave_set, queue, drain, failed = inst.set_real_method, inst.log_queue, inst.drain_log, inst.failed

    def set_values(t):
        try:
            slave_set(vrs, values[lo:lo + n] if aliased else [values[j] for j in positions])
        except BaseException as exc:
            raise failed("[setReal]", "fmi2SetReal", exc, t) from None
        if queue:
            drain()
    return set_values
