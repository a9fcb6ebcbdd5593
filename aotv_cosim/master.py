"""The co-simulation master: fixed communication step, Gauss-Seidel or Jacobi, on FMPy.

Initialization: every FMU is instantiated, its parameters and unconnected inputs are set, all
enter initialization mode, and connected values are propagated output -> input in an order that
respects each FMU's declared initial dependencies, so a guidance law sees the vehicle's entry
state and the vehicle sees the first command before the first step.

Stepping (Gauss-Seidel, default): components are stepped in `System.gauss_seidel_order()`; an
input whose source was already stepped in this sweep ('fresh') is set just before its component
steps; the others ('delayed') are set at the end of the sweep, so every component starts the next
step with inputs from the newest outputs. Outputs that feed through from delayed inputs are read
again after those are set, so recorded values are consistent at each communication point.
Jacobi: every component steps from the same communication point, then all outputs are read and
all inputs set, the scheme of OSP libcosim's fixed-step algorithm.

The loop keeps per-component value-reference and value arrays made once (outputs are views into
one shared ctypes buffer that numpy also sees), calls the C entry points directly, and records a
numpy copy of the buffer per communication point. Non-finite values are searched for in whole
chunks when they are flushed, not per step.
"""

import ctypes
import math
import time as clock
from dataclasses import dataclass, field

import numpy as np

from aotv_cosim.errors import InputError, SimulationError
from aotv_cosim.fmi_instance import FmuInstance

CHUNK = 1000
"""Communication points recorded between two flushes to the result files."""


class Interrupted(Exception):
    """Raised by a signal handler to stop a run cleanly (SIGINT, SIGTERM)."""


@dataclass
class Outcome:
    """What a run produced besides its time series."""

    status: str = "completed"
    stop_reason: str = "stop time reached"
    event: dict = None
    error: str = None
    error_detail: dict = None
    steps: int = 0
    wall_time: float = 0.0
    init_time: float = 0.0
    fmus: dict = field(default_factory=dict)


def signals_to_read(scenario):
    """Every output the master reads: connected sources, records, stop and expectation signals."""
    wanted = [f"{c.source}.{c.output}" for c in scenario.system.connections]
    wanted += scenario.record + [c.signal for c in scenario.stop_conditions]
    wanted += [e.signal for e in scenario.expectations]
    wanted += [s for p in scenario.plots for s in p["signals"] + [p.get("x", "time")] if s != "time"]
    return list(dict.fromkeys(wanted))


class _Plan:
    """Arrays and index maps of one component, built once before stepping."""

    def __init__(self, inst, outputs, values, offset):
        self.inst = inst
        self.n_out = len(outputs)
        self.out_vrs = (ctypes.c_uint * self.n_out)(*[inst.info.variables[o].vr for o in outputs])
        self.out_vals = (ctypes.c_double * self.n_out).from_buffer(values, offset * 8)
        self.offset = offset

    def inputs(self, names, sources):
        """(vr array, value array, [(input slot, buffer index)]) for the given inputs."""
        vrs = (ctypes.c_uint * len(names))(*[self.inst.info.variables[n].vr for n in names])
        vals = (ctypes.c_double * len(names))()
        return vrs, vals, list(enumerate(sources))


class Master:
    """Runs one Scenario; `record(times, rows)` receives chunks of recorded rows as they come."""

    def __init__(self, scenario, record, progress=None):
        self.scenario = scenario
        self.record = record
        self.progress = progress
        self.signals = signals_to_read(scenario)
        self.instances = {}

    # ---- set-up -----------------------------------------------------------------------------
    def _instantiate(self, outcome):
        s = self.scenario
        for name, comp in s.system.components.items():
            self.instances[name] = FmuInstance(name, comp.fmu, s.start, s.stop)
            outcome.fmus[name] = {"fmu": comp.fmu_ref, "file": str(comp.fmu.path),
                                  "guid": comp.fmu.guid}
        for name, comp in s.system.components.items():
            self.instances[name].set_values(comp.parameters)

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
                    value = self.instances[conn.source].get_real([conn.output])
                    self.instances[conn.target].set_real([conn.input], value)
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
        order = system.gauss_seidel_order()
        position = {name: k for k, name in enumerate(order)}
        by_comp = {name: [sig.split(".", 1)[1] for sig in self.signals if sig.split(".", 1)[0] == name]
                   for name in order}
        # Put outputs that feed through from delayed inputs last, so they can be re-read as a tail.
        sources = system.source_of()
        delayed = {name: [inp for (tgt, inp), (src, _) in sources.items() if tgt == name and
                          (s.algorithm == "jacobi" or position[src] >= position[name])]
                   for name in order}
        tails = {}
        for name in order:
            ft = system.components[name].fmu.feedthrough
            tail = [o for o in by_comp[name] if ft.get(o, set()) & set(delayed[name])]
            by_comp[name] = [o for o in by_comp[name] if o not in tail] + tail
            tails[name] = len(tail)
        total = sum(len(v) for v in by_comp.values())
        self.values = (ctypes.c_double * max(total, 1))()
        self.array = np.frombuffer(self.values, dtype=np.float64)[:total]
        self.index, plans, offset = {}, [], 0
        for name in order:
            plan = _Plan(self.instances[name], by_comp[name], self.values, offset)
            for k, out in enumerate(by_comp[name]):
                self.index[f"{name}.{out}"] = offset + k
            offset += plan.n_out
            plans.append(plan)
        for plan in plans:
            name = plan.inst.name
            fresh = [inp for (tgt, inp), (src, _) in sources.items()
                     if tgt == name and inp not in delayed[name]]
            plan.fresh = plan.inputs(fresh, [self.index[".".join(sources[(name, i)])] for i in fresh])
            plan.delayed = plan.inputs(delayed[name],
                                       [self.index[".".join(sources[(name, i)])] for i in delayed[name]])
            n_tail = tails[name]
            first = plan.n_out - n_tail
            plan.tail = (n_tail, (ctypes.c_uint * n_tail)(*plan.out_vrs[first:]),
                         (ctypes.c_double * n_tail).from_buffer(self.values, (plan.offset + first) * 8))
        self.plans = plans
        self.order = order

    # ---- stepping ----------------------------------------------------------------------------
    def _read_all(self, t):
        for p in self.plans:
            if p.n_out and p.inst.raw_get_real(p.inst.component, p.out_vrs, p.n_out, p.out_vals) > 1:
                raise p.inst.failure("fmi2GetReal", t)

    def _set_inputs(self, which, t):
        values = self.values
        for p in self.plans:
            vrs, vals, pairs = getattr(p, which)
            if pairs:
                for i, j in pairs:
                    vals[i] = values[j]
                if p.inst.raw_set_real(p.inst.component, vrs, len(pairs), vals) > 1:
                    raise p.inst.failure("fmi2SetReal", t)

    def _read_tails(self, t):
        for p in self.plans:
            n, vrs, vals = p.tail
            if n and p.inst.raw_get_real(p.inst.component, vrs, n, vals) > 1:
                raise p.inst.failure("fmi2GetReal", t)

    def run(self) -> Outcome:
        """Run the scenario to its stop time or stop condition; never raises for a failed run."""
        outcome = Outcome()
        wall0 = clock.perf_counter()
        s = self.scenario
        rows = Rows(self, outcome)
        try:
            self._instantiate(outcome)
            self._initialize()
            self._build_plans()
            self._read_all(s.start)
            self._set_inputs("fresh", s.start)
            self._set_inputs("delayed", s.start)
            self._read_tails(s.start)
            outcome.init_time = clock.perf_counter() - wall0
            rows.add(s.start, force=True)
            self._loop(rows, outcome)
        except SimulationError as exc:
            outcome.status, outcome.error = "failed", str(exc)
            outcome.stop_reason = f"failure in {getattr(exc, 'component', '?')}"
            outcome.error_detail = {"component": getattr(exc, "component", None),
                                    "variable": getattr(exc, "variable", None),
                                    "time": getattr(exc, "time", None), "message": exc.cause}
        except (KeyboardInterrupt, Interrupted):
            outcome.status, outcome.stop_reason = "interrupted", "interrupted by a signal"
        finally:
            try:
                rows.flush()
            except SimulationError as exc:  # non-finite value found in the last chunk
                outcome.status, outcome.error = "failed", str(exc)
                outcome.stop_reason = "non-finite value"
                outcome.error_detail = {"component": exc.component, "variable": exc.variable,
                                        "time": exc.time, "message": exc.cause}
            for inst in self.instances.values():
                inst.close()
            outcome.wall_time = clock.perf_counter() - wall0
        return outcome

    def _loop(self, rows, outcome):
        s = self.scenario
        plans, values, array = self.plans, self.values, self.array
        start, h, stop = s.start, s.step, s.stop
        n_steps = max(1, math.ceil((stop - start) / h - 1e-9))
        jacobi = s.algorithm == "jacobi"
        conditions = [(self.index[c.signal], c.threshold, c.direction, c) for c in s.stop_conditions]
        previous = array.copy()
        have_tails = any(p.tail[0] for p in plans)
        steppers = [(p, p.inst.component, p.inst.raw_do_step, p.inst.raw_get_real, p.inst.raw_set_real,
                     p.out_vrs, p.out_vals, p.n_out) + p.fresh for p in plans]
        report_every = max(1, n_steps // 200)
        for k in range(n_steps):
            t = start + k * h
            step = min(h, stop - t) if k == n_steps - 1 else h
            if jacobi:
                for p, c, do_step, get, _set, ovrs, ovals, n_out, *_ in steppers:
                    status = do_step(c, t, step, 1)
                    if status > 1:
                        raise p.inst.failure("fmi2DoStep", t, status)
                for p, c, _do, get, _set, ovrs, ovals, n_out, *_ in steppers:
                    if n_out and get(c, ovrs, n_out, ovals) > 1:
                        raise p.inst.failure("fmi2GetReal", t + step)
            else:
                for p, c, do_step, get, set_, ovrs, ovals, n_out, fvrs, fvals, fpairs in steppers:
                    if fpairs:
                        for i, j in fpairs:
                            fvals[i] = values[j]
                        if set_(c, fvrs, len(fpairs), fvals) > 1:
                            raise p.inst.failure("fmi2SetReal", t)
                    status = do_step(c, t, step, 1)
                    if status > 1:
                        raise p.inst.failure("fmi2DoStep", t, status)
                    if n_out and get(c, ovrs, n_out, ovals) > 1:
                        raise p.inst.failure("fmi2GetReal", t + step)
            t_new = start + (k + 1) * h if k < n_steps - 1 else stop
            self._set_inputs("delayed", t_new)
            if have_tails:
                self._read_tails(t_new)
            outcome.steps = k + 1
            for idx, threshold, direction, cond in conditions:
                before, now = previous[idx], values[idx]
                up = before < threshold <= now
                down = before > threshold >= now
                if (up and direction != "down") or (down and direction != "up"):
                    fraction = (threshold - before) / (now - before)
                    outcome.event = rows.event(cond, t, t_new, fraction, previous)
                    outcome.stop_reason = (f"{cond.signal} crossed {threshold:g} "
                                           f"{'up' if up else 'down'} at t = {outcome.event['time']:.6g} s")
                    rows.add(t_new, force=True)
                    return
            if conditions:
                previous[:] = array
            rows.add(t_new, force=k == n_steps - 1)
            if self.progress and k % report_every == 0:
                self.progress(t_new)


class Rows:
    """Recorded communication points: a growing buffer flushed in chunks to `master.record`."""

    def __init__(self, master, outcome):
        self.master = master
        self.outcome = outcome
        self.every = master.scenario.record_every
        self.count = 0
        self.times, self.rows = [], []

    def add(self, t, force=False):
        self.count += 1
        if force or (self.count - 1) % self.every == 0:
            self.times.append(t)
            self.rows.append(self.master.array.copy())
            if len(self.rows) >= CHUNK:
                self.flush()

    def flush(self):
        if not self.rows:
            return
        times, rows = np.array(self.times), np.vstack(self.rows)
        self.times, self.rows = [], []
        bad = ~np.isfinite(rows)
        if bad.any():
            r, col = np.argwhere(bad)[0]
            self.master.record(times[:r + 1], rows[:r + 1])
            raise self._non_finite(col, times[r])
        self.master.record(times, rows)

    def _non_finite(self, col, t):
        signal = next(sig for sig, i in self.master.index.items() if i == col)
        comp, var = signal.split(".", 1)
        inst = self.master.instances[comp]
        error = SimulationError(f"output {var} is not finite at t = {t:.6g} s",
                                file=inst.info.path.name, entry=signal,
                                fix="check the inputs and parameters of this component")
        error.component, error.variable, error.time = comp, var, float(t)
        return error

    def event(self, cond, t0, t1, fraction, previous):
        """The stop condition's crossing, linearly interpolated between two communication points."""
        values = previous + fraction * (self.master.array - previous)
        return {"signal": cond.signal, "threshold": cond.threshold, "time": t0 + fraction * (t1 - t0),
                "values": {sig: float(values[i]) for sig, i in self.master.index.items()}}
