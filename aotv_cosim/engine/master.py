"""The co-simulation master: fixed communication step, Gauss-Seidel or Jacobi, on FMPy.

Initialization: every FMU is instantiated, its parameters and unconnected inputs are set, all
enter initialization mode, and connected values are propagated output -> input in an order that
respects each FMU's declared initial dependencies, so a guidance law sees the vehicle's entry
state and the vehicle sees the first command before the first step.

Stepping (Gauss-Seidel, default): components are stepped in `ordering.gauss_seidel_order` and
values propagate in a topological order of variables (`ordering.sweep`): connections plus each
FMU's declared output -> input feedthrough. An input whose source output is already final at
the new communication point ('fresh') is set just before its component steps; the others
('delayed') are set as soon as their source is final, after their component stepped. Outputs
that feed through from a delayed input are read again once it is set, before anything that
needs them: with vehicle.h -> atmosphere.h, atmosphere.rho -> vehicle.rho and
vehicle.drag_acc -> guidance.drag, the atmosphere steps after the vehicle, vehicle.rho is set and
drag_acc re-read, then the guidance steps with the drag from the new density. So every
component starts the next step with inputs from the newest outputs and recorded values are
consistent at each communication point; only a true algebraic loop (a cycle of feedthrough
between variables) is refused, when the wiring is loaded.
Jacobi: every component steps from the same communication point, then all outputs are read and
all inputs set, the scheme of OSP libcosim's fixed-step algorithm.

Inputs held over a step (default) give a coupling error first order in the step; with the
scenario's "step": {"inputs": "extrapolated"} the delayed inputs get the mean over the coming
step of their sources' linear extrapolation, which makes it second order (`_end_of_sweep`).

The loop keeps per-component value-reference and value arrays made once: outputs are views into
one shared ctypes buffer that numpy also sees, and inputs whose sources lie side by side in that
buffer are passed as views of it (no copy per step). It calls the C entry points directly and
records the bytes of the buffer per communication point. Non-finite values are searched for in
whole chunks when they are flushed, not per step; with decimated recording, a step not recorded
is summed (a non-finite sum is checked element-wise) and kept if it holds a non-finite value, so
the first one is found where it was produced. A `pool` kept by the caller lets a sequence
of runs (Monte Carlo) reset the FMUs instead of instantiating them again.
"""

import ctypes
import math
import time as clock
from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from aotv_cosim.engine import interrupts, ordering, step_doubling, watchdog
from aotv_cosim.engine.capabilities import fixed_step_components
from aotv_cosim.errors import InputError, SimulationError, TerminateRequest
from aotv_cosim.engine.interrupts import Interrupted
from aotv_cosim.engine.fmi_calls import Plan, bind, calls_by_type, run_bound
from aotv_cosim.engine.fmi_instance import FmuInstance
from aotv_cosim.engine.rows import CHUNK, Recorder, Rows
from aotv_cosim.engine.ranges import RangeWatch, range_watches
from aotv_cosim.engine.scenario import crossing
from aotv_cosim.engine.variable_types import Strings
from aotv_cosim.status import Status

@dataclass
class Outcome:
    """What a run produced besides its time series."""

    status: Status = Status.COMPLETED
    stop_reason: str = "stop time reached"
    event: Optional[dict] = None
    """The located stop-condition crossing (`rows.Rows.event`), or None."""
    error: Optional[str] = None
    error_detail: Optional[dict] = None
    """The failure's component, variable, time (s) and message, or None."""
    steps: int = 0
    wall_time: float = 0.0
    """Wall-clock time of the whole run, s."""
    init_time: float = 0.0
    """Wall-clock time of instantiation and initialization, s."""
    loop_time: float = 0.0
    """Wall-clock time of the stepping loop, s."""
    fmus: dict = field(default_factory=dict)
    terminate_request: Optional[dict] = None
    """An FMU that asked to end the run: its component, the last communication point every
    component reached and the FMU's fmi2LastSuccessfulTime (s)."""
    step_control: Optional[dict] = None
    """Error-controlled runs (`engine.step_doubling`): steps accepted, rejected, kept at the min
    bound, sweeps made, smallest and largest step (s)."""


def signals_to_read(scenario):
    """Every output the master reads: connected sources, records, stop and expectation signals."""
    wanted = [f"{c.source}.{c.output}" for c in scenario.system.connections]
    wanted += scenario.record + [c.signal for c in scenario.stop_conditions]
    wanted += [e.signal for e in scenario.expectations]
    wanted += list(scenario.step_control.tolerance) if scenario.step_control else []
    wanted += [s for p in scenario.plots for s in p["signals"] + [p.get("x", "time")] if s != "time"]
    return list(dict.fromkeys(wanted))


class Master:
    """Runs one Scenario; `run(recorder)` passes the recorder chunks of recorded rows as they come."""

    def __init__(self, scenario, progress=None, overrides=None, pool=None):
        """progress(t): told the time (s) now and then; overrides: {'comp.var': value} set after
        the wiring's values (a Monte Carlo draw); pool: a dict kept by the caller between runs,
        {name: FmuInstance}: its instances are reset (fmi2Reset) instead of instantiated again,
        and left open at the end of the run."""
        self.scenario = scenario
        self.record = None
        """The `record` of the recorder of the run under way (`rows.Rows` flushes to it)."""
        self.progress = progress
        self.overrides = overrides or {}
        self.pool = pool
        self.signals = signals_to_read(scenario)
        self.instances = {}
        self.converted = False
        """True when a delayed Real input takes a converted Integer or Boolean output (held, not
        extrapolated: `_end_of_sweep`)."""
        self.strings = Strings()
        """The String values of the run, numbered (`variable_types`): the buffer holds their numbers."""

    # ---- set-up -----------------------------------------------------------------------------
    def _instantiate(self, outcome):
        s = self.scenario
        kept = self.pool if self.pool is not None else {}
        for name, comp in s.system.components.items():
            inst = kept.get(name)
            if inst is not None and inst.info is comp.fmu and not inst.broken:
                inst.reset(s.start, s.stop)
            else:
                inst = FmuInstance(name, comp.fmu, s.start, s.stop)
            self.instances[name] = kept[name] = inst
            outcome.fmus[name] = {"fmu": comp.fmu_ref, "file": str(comp.fmu.path),
                                  "guid": comp.fmu.guid}
        drawn = {}
        for signal, value in self.overrides.items():
            comp, var = signal.split(".", 1)
            drawn.setdefault(comp, {})[var] = value
        for name, comp in s.system.components.items():
            self.instances[name].set_values({**comp.parameters, **drawn.get(name, {})})

    def _initialize(self):
        """Enter initialization, propagate connected values in dependency order, exit."""
        system = self.scenario.system
        for inst in self.instances.values():
            inst.enter_initialization()
        pending = list(system.connections)
        done_inputs = set()
        connected_inputs = {(c.target, c.input) for c in pending}
        while pending:
            progressed = False
            for conn in list(pending):
                deps = system.components[conn.source].fmu.initial_feedthrough.get(conn.output, set())
                if all((conn.source, d) in done_inputs or (conn.source, d) not in connected_inputs
                       for d in deps):
                    value = self.instances[conn.source].get_value(conn.output)
                    self.instances[conn.target].set_values({conn.input: value})
                    done_inputs.add((conn.target, conn.input))
                    pending.remove(conn)
                    progressed = True
            if not progressed:
                raise InputError("algebraic loop in initialization: " + ", ".join(map(str, pending)),
                                 file=system.path, entry="connections",
                                 fix="break the loop with a component without direct feedthrough")
        for inst in self.instances.values():
            inst.exit_initialization()

    def _build_plans(self):
        s = self.scenario
        system = s.system
        sources = system.source_of()
        # Connected outputs first, in connection order, so that the inputs a component takes
        # from one source sit side by side in the buffer and are passed without a copy.
        connected = list(dict.fromkeys(f"{c.source}.{c.output}" for c in system.connections))
        signals = connected + [sig for sig in self.signals if sig not in connected]
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
        self.array = np.frombuffer(self.values, dtype=np.float64)[:total]
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

    # ---- stepping ----------------------------------------------------------------------------
    def _read_all(self, t):
        for p in self.plans:
            if p.n_out and p.inst.raw_get_real(p.inst.component, p.out_vrs, p.out_size, p.out_vals) > 1:
                raise p.inst.failure("fmi2GetReal", t)
            if p.after:
                run_bound(bind(p.after), self.values, t)

    def run(self, recorder: Recorder) -> Outcome:
        """Run the scenario to its stop time or stop condition, the recorded rows passed to
        `recorder` in chunks (the columns laid out as `self.index` says, known once it runs);
        never raises for a failed run."""
        outcome = Outcome()
        wall0 = clock.perf_counter()
        s = self.scenario
        self.record = recorder.record
        rows = Rows(self, outcome)
        try:
            self._instantiate(outcome)
            self._initialize()
            self._build_plans()
            self._read_all(s.start)
            run_bound(bind(self.start), self.values, s.start)
            outcome.init_time = clock.perf_counter() - wall0
            rows.add(s.start)
            with watchdog.armed(s.step_timeout):
                self._loop(rows, outcome)
            outcome.loop_time = clock.perf_counter() - wall0 - outcome.init_time
        except SimulationError as exc:
            outcome.status, outcome.error = Status.FAILED, str(exc)
            outcome.stop_reason = f"failure in {exc.component}" if exc.component else "output failed"
            outcome.error_detail = {"component": exc.component, "variable": exc.variable,
                                    "time": exc.time, "message": exc.cause}
        except TerminateRequest as request:
            self._terminated(request, rows, outcome)
        except (KeyboardInterrupt, Interrupted):
            outcome.status = Status.INTERRUPTED
            outcome.stop_reason = f"interrupted by {interrupts.name() or 'SIGINT'}"
        finally:
            try:
                rows.flush()
            except SimulationError as exc:  # non-finite value in the last chunk, or a write failed
                outcome.status, outcome.error = Status.FAILED, str(exc)
                outcome.stop_reason = "non-finite value" if exc.component else "output failed"
                outcome.error_detail = {"component": exc.component, "variable": exc.variable,
                                        "time": exc.time, "message": exc.cause}
            for name, inst in self.instances.items():
                if self.pool is None or inst.broken:
                    inst.close()
                    if self.pool is not None:
                        del self.pool[name]
            outcome.wall_time = clock.perf_counter() - wall0
        return outcome

    def _terminated(self, request, rows, outcome):
        """End the run cleanly at an FMU's terminate request. The rows up to the last
        communication point every component reached are kept; an FMU run alone also gets a last
        row at its fmi2LastSuccessfulTime, its outputs read there (as fmpy.simulate_fmu does).
        In a system the other components have already stepped past that time, or not yet, so no
        consistent row exists there."""
        last = request.last_successful_time
        outcome.status = Status.TERMINATED
        when = last if last is not None else request.time
        outcome.stop_reason = f"{request.component} asked to terminate at t = {when:.6g} s"
        outcome.terminate_request = {"component": request.component, "communication_point": request.time,
                                     "last_successful_time": last}
        if len(self.instances) == 1 and last is not None and last > request.time:
            try:
                self._read_all(last)
            except SimulationError:  # the FMU gives no values after its request: none recorded there
                return
            rows.add(last)

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
        finish = bind(self.finish)
        if self.scenario.inputs != "extrapolated":
            return finish, None
        values = self.values
        lines = [(p.inst, p.inst.component, p.inst.raw_set_real, p.delayed.vrs, p.delayed.size,
                  p.delayed.vals, tuple(enumerate(p.delayed.positions)))
                 for p in self.plans if p.delayed.n]

        def extrapolate(t, h, h_next, last):
            c_slope = 0.5 * h_next / h
            for inst, c, set_, vrs, size, vals, slots in lines:
                for i, j in slots:  # a few values: plain floats cost less than numpy here
                    now = values[j]
                    vals[i] = now + c_slope * (now - last[j])
                if set_(c, vrs, size, vals) > 1:
                    raise inst.failure("fmi2SetReal", t)
        exact = any(is_get or what != "fmi2SetReal" for is_get, *_, what in finish) or self.converted
        return (finish if exact else []), extrapolate

    def sweeper(self, finish):
        """advance(t, step, t_new): one communication step of every component from t, values
        exchanged as `ordering.sweep` says (Gauss-Seidel) or all after all stepped (Jacobi), then
        the bound `finish` calls; the buffer then holds the outputs at t_new."""
        values = self.values
        steppers = [(p.inst, p.inst.component, p.inst.raw_do_step, p.inst.raw_get_real,
                     p.inst.raw_set_real, p.out_vrs, p.out_vals, p.n_fresh_out, p.fresh_out_size,
                     p.fresh.vrs, p.fresh.vals, p.fresh.pairs, p.fresh.n, p.fresh.size,
                     bind(p.before), bind(p.after)) for p in self.plans]
        now, length, new_step = ctypes.c_double(), ctypes.c_double(), ctypes.c_int(1)

        def jacobi(t, step, t_new):
            now.value, length.value = t, step
            for inst, c, do_step, get, set_, ovrs, ovals, n_out, osize, *_ in steppers:
                status = do_step(c, now, length, new_step)
                if status > 1:
                    raise inst.refused_step(t, status)
            for inst, c, _do, get, set_, ovrs, ovals, n_out, osize, *_, after in steppers:
                if n_out and get(c, ovrs, osize, ovals) > 1:
                    raise inst.failure("fmi2GetReal", t_new)
                if after:
                    run_bound(after, values, t_new)
            run_bound(finish, values, t_new)

        def gauss_seidel(t, step, t_new):
            now.value, length.value = t, step
            for (inst, c, do_step, get, set_, ovrs, ovals, n_out, osize, fvrs, fvals, pairs, nf,
                 fsize, before, after) in steppers:
                if before:
                    run_bound(before, values, t_new)
                if nf:
                    for i, j in pairs:
                        fvals[i] = values[j]
                    if set_(c, fvrs, fsize, fvals) > 1:
                        raise inst.failure("fmi2SetReal", t)
                status = do_step(c, now, length, new_step)
                if status > 1:
                    raise inst.refused_step(t, status)
                if n_out and get(c, ovrs, osize, ovals) > 1:
                    raise inst.failure("fmi2GetReal", t_new)
                if after:
                    run_bound(after, values, t_new)
            run_bound(finish, values, t_new)
        return watchdog.limited(jacobi if self.scenario.algorithm == "jacobi" else gauss_seidel,
                                self.scenario.step_timeout)

    def watches(self):
        """(buffer index, threshold, direction, condition) of every stop condition and range watch."""
        s = self.scenario
        return [(self.index[c.signal], c.threshold, c.direction, c)
                for c in [*s.stop_conditions, *range_watches(s.system, self.index)]]

    def stop_at(self, rows, outcome, cond, up, event):
        """End the run at a stop condition's crossing `event` (`Rows.event`): say why, and mark the
        run impact or out_of_range when the condition is a RangeWatch."""
        outcome.event = event
        outcome.stop_reason = (f"{cond.signal} changed at t = {event['time']:.6g} s" if cond.threshold is None
                               else f"{cond.signal} crossed {cond.threshold:g} "
                               f"{'up' if up else 'down'} at t = {event['time']:.6g} s")
        if isinstance(cond, RangeWatch):  # an output left its declared range
            outcome.status = cond.status
            outcome.error = f"{cond.message} at t = {event['time']:.6g} s"

    def _loop(self, rows, outcome):
        if self.scenario.step_control is not None:
            return step_doubling.loop(self, rows, outcome)
        s = self.scenario
        values, array = self.values, self.array
        start, h, stop = s.start, s.step, s.stop
        n_steps = max(1, math.ceil((stop - start) / h - 1e-9))
        # an FMU that cannot vary its step gets h for the last one too (stop is start + n h,
        # `capabilities.check_capabilities`), not stop - t, which rounding makes differ from h;
        # the last point recorded is then the time it reached, start + n h
        fixed_only = bool(fixed_step_components(s.system))
        conditions = self.watches()
        watched = [idx for idx, *_ in conditions]
        before_values = [values[idx] for idx in watched]  # the watched signals at t
        last_row = bytes(values)  # the whole buffer at t, for an event's interpolation
        finish, extrapolate = self._end_of_sweep()
        advance = self.sweeper(finish)
        last_values = type(values).from_buffer_copy(values)  # the buffer one step ago
        size = ctypes.sizeof(values)
        every = s.record_every
        keep_time, keep_row = rows.times.append, rows.rows.append
        progress = self.progress
        report_every = max(1, n_steps // 200)
        stop_requested = interrupts.RECEIVED
        done = 0
        try:
            for k in range(n_steps):
                if stop_requested:
                    raise Interrupted(interrupts.name())
                t = start + k * h
                last = k == n_steps - 1
                step = (h if fixed_only else stop - t) if last else h
                t_new = stop if last and not fixed_only else start + (k + 1) * h
                advance(t, step, t_new)
                if extrapolate is not None:
                    extrapolate(t_new, step, h if k < n_steps - 2 else stop - t_new, last_values)
                    ctypes.memmove(last_values, values, size)
                done = k + 1
                for (idx, threshold, direction, cond), before in zip(conditions, before_values):
                    now = values[idx]
                    up = crossing(before, now, threshold, direction)
                    if up is not None:
                        # a discrete signal's value changes at a communication point: no interpolation
                        fraction = None if threshold is None or self.types[cond.signal] != "Real" \
                            else (threshold - before) / (now - before)
                        previous = np.frombuffer(last_row, dtype=np.float64)[:array.size]
                        self.stop_at(rows, outcome, cond, up, rows.event(cond, t, t_new, fraction, previous))
                        rows.add(t_new)
                        return
                if conditions:
                    before_values = [values[idx] for idx in watched]
                    last_row = bytes(values)
                if done % every == 0 or last or not (every == 1 or math.isfinite(sum(values))
                                                     or np.isfinite(array).all()):
                    # a step left out by record_every is kept if it holds the first non-finite
                    # value, so the chunk check blames the component that produced it, then
                    keep_time(t_new)
                    keep_row(last_row if conditions else bytes(values))
                    if len(rows.rows) >= CHUNK:
                        rows.flush()
                if progress and k % report_every == 0:
                    progress(t_new)
        finally:
            outcome.steps = done
