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
step of their sources' linear extrapolation, which makes it second order
(`coupling.Coupling._end_of_sweep`).

The values exchanged and one communication step belong to the run's `coupling.Coupling`: outputs
are views into one shared ctypes buffer that numpy also sees, inputs whose sources lie side by side
in that buffer are passed as views of it (no copy per step), and the C entry points are called
directly, or, for the FMUs this package built, their Python slaves (`fmi_calls` "direct",
`direct_instance`). The loop records the bytes of the buffer per communication point. Non-finite values are searched for
in whole chunks when they are flushed, not per step; with decimated recording, a step not recorded
is summed (a non-finite sum is checked element-wise) and kept if it holds a non-finite value, so
the first one is found where it was produced. A `pool` kept by the caller lets a sequence
of runs (Monte Carlo) reset the FMUs instead of instantiating them again.
"""

import contextlib
import ctypes
import math
import os
import time as clock
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import cast

import numpy as np

from aotv_cosim.fmu.build import built_wrapper
from aotv_cosim.simulation import interrupts, step_doubling, watchdog
from aotv_cosim.model.capabilities import fixed_step_components
from aotv_cosim.simulation.coupling import Coupling
from aotv_cosim.simulation.direct_instance import DirectInstance, built_here
from aotv_cosim.errors import InputError, SimulationError, TerminateRequest
from aotv_cosim.simulation.instance import FmuInstance
from aotv_cosim.simulation.interrupts import Interrupted
from aotv_cosim.simulation.fmi2_instance import Fmi2Instance
from aotv_cosim.simulation.fmi3_instance import Fmi3Instance
from aotv_cosim.simulation.rows import CHUNK, Recorder, Rows
from aotv_cosim.model.bindings import bound_values
from aotv_cosim.model.ranges import RangeWatch
from aotv_cosim.model.scenario import crossing
from aotv_cosim.model.variable_types import Strings
from aotv_cosim.status import Status

@dataclass
class Outcome:
    """What a run produced besides its time series."""

    status: Status = Status.COMPLETED
    stop_reason: str = "stop time reached"
    event: dict | None = None
    """The located stop-condition crossing (`rows.Rows.event`), or None."""
    error: str | None = None
    error_detail: dict | None = None
    """The failure's component, variable, time (s) and message, or None."""
    steps: int = 0
    wall_time: float = 0.0
    """Wall-clock time of the whole run, s."""
    init_time: float = 0.0
    """Wall-clock time of instantiation and initialization, s."""
    loop_time: float = 0.0
    """Wall-clock time of the stepping loop, s."""
    fmus: dict = field(default_factory=dict)
    terminate_request: dict | None = None
    """An FMU that asked to end the run: its component, the last communication point every
    component reached and the FMU's fmi2LastSuccessfulTime (s)."""
    step_control: dict | None = None
    """Error-controlled runs (`simulation.step_doubling`): steps accepted, rejected, kept at the min
    bound, sweeps made, smallest and largest step (s)."""


FMI_CALLS = ("c", "direct")
"""How the master calls FMUs: "c", through each FMU's FMI C library (FMPy); "direct", the FMUs
built by this package called in this interpreter (`direct_instance.DirectInstance`), every
other FMU through its C library."""
FMI_CALLS_DEFAULT = "direct"
"""The FMUs built here called directly: the same results to the bit on every shipped scenario
(tests/simulation/test_direct_calls.py), the whole step about 0.75-0.8x of the lean C path's and 0.55-0.6x
of the stock one's (bench/bench_fmi_calls.py)."""


C_INSTANCES = {"2.0": Fmi2Instance, "3.0": Fmi3Instance}
"""fmiVersion -> the `instance.FmuInstance` that calls such an FMU through its C library."""


def instance_class(info, fmi_calls: str) -> Callable[..., FmuInstance]:
    """The `instance.FmuInstance` implementation that runs the FMU `info` when the run asks for
    `fmi_calls`: an FMU this package built called directly when asked ("direct"), every other
    one through its C library for its FMI version."""
    if fmi_calls == "direct" and built_here(info):
        return DirectInstance
    return C_INSTANCES[info.fmi_version]


def signals_to_read(scenario):
    """Every output the master reads: connected sources, records, stop and expectation signals."""
    wanted = [f"{c.source}.{c.output}" for c in scenario.system.connections]
    wanted += scenario.record + [c.signal for c in scenario.stop_conditions]
    wanted += [e.signal for e in scenario.expectations]
    wanted += list(scenario.step_control.tolerance) if scenario.step_control else []
    wanted += [s for p in scenario.plots for s in p["signals"] + [p.get("x", "time")] if s != "time"]
    return list(dict.fromkeys(wanted))


class ProcessExit(Exception):
    """An FMU's code called os._exit while the master ran it (`exits_refused`)."""


@contextlib.contextmanager
def exits_refused():
    """While inside, os._exit raises ProcessExit where it is called instead of ending the process:
    FMUs run their Python code in this process, and a law's os._exit(0) in do_step ended `run`
    with exit status 0, no summary.json and the time series left as a .part file. The FMU reports
    the exception as any other (fmi2Fatal), so the run fails naming it and its rows are kept."""
    real = os._exit

    def refused(status):
        raise ProcessExit(f"os._exit({status!r}) was called; an FMU must not end the process")

    os._exit = refused
    try:
        yield
    finally:
        os._exit = real


class Master:
    """Runs one Scenario; `run(recorder)` passes the recorder chunks of recorded rows as they come."""

    def __init__(self, scenario, progress=None, overrides=None, pool=None, fmi_calls=None):
        """progress(t): told the time (s) now and then; overrides: {'comp.var': value} set after
        the wiring's values (a Monte Carlo draw); pool: a dict kept by the caller between runs,
        {name: FmuInstance}: its instances are reset (fmi2Reset) instead of instantiated again,
        and left open at the end of the run; fmi_calls: "c" (every FMU through its FMI C
        library) or "direct" (the FMUs built by this package called in this interpreter,
        `direct_instance`), default `FMI_CALLS_DEFAULT`."""
        if (fmi_calls or FMI_CALLS_DEFAULT) not in FMI_CALLS:
            raise ValueError(f"fmi_calls must be one of {', '.join(FMI_CALLS)}, not {fmi_calls!r}")
        self.fmi_calls = fmi_calls or FMI_CALLS_DEFAULT
        self.scenario = scenario
        self.record = None
        """The `record` of the recorder of the run under way (`rows.Rows` flushes to it)."""
        self.progress = progress
        self.overrides = overrides or {}
        self.pool = pool
        self.signals = signals_to_read(scenario)
        self.instances = {}
        self.coupling = cast(Coupling, None)  # None until `_build_plans`, which every run calls first
        """The run's `Coupling` (buffer and prepared calls), made after initialization."""
        self.strings = Strings()
        """The String values of the run, numbered (`variable_types`): the buffer holds their numbers."""

    # ---- set-up -----------------------------------------------------------------------------
    def _instantiate(self, outcome):
        s = self.scenario
        kept = self.pool if self.pool is not None else {}
        for name, comp in s.system.components.items():
            kind = instance_class(comp.fmu, self.fmi_calls)
            inst = kept.get(name)
            if inst is not None and inst.info is comp.fmu and not inst.broken and type(inst) is kind:
                inst.reset(s.start, s.stop)
            else:
                if inst is not None and not inst.broken:
                    inst.close()  # a pooled instance of another FMU or call path
                inst = kind(name, comp.fmu, s.start, s.stop)
            self.instances[name] = kept[name] = inst
            outcome.fmus[name] = {"fmu": comp.fmu_ref, "file": str(comp.fmu.path),
                                  "guid": comp.fmu.guid, "fmi_calls": inst.calls,
                                  "wrapper": built_wrapper(comp.fmu.path)}
        drawn: dict = {}
        for signal, value in {**self.overrides, **bound_values(s, self.overrides)}.items():
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
        """The run's `Coupling`: its buffer and the calls prepared over it."""
        self.coupling = Coupling(self.scenario, self.instances, self.signals, self.strings)

    @property
    def index(self) -> dict:
        """{'comp.var': position} of every recorded signal in a row (the coupling's buffer)."""
        return self.coupling.index

    # ---- stepping ----------------------------------------------------------------------------
    def _read_all(self, t):
        self.coupling.read_all(t)

    def run(self, recorder: Recorder) -> Outcome:
        """Run the scenario to its stop time or stop condition, the recorded rows passed to
        `recorder` in chunks (the columns laid out as `self.index` says, known once it runs);
        never raises for a failed run."""
        with exits_refused():
            return self._run(recorder)

    def _run(self, recorder: Recorder) -> Outcome:
        outcome = Outcome()
        wall0 = clock.perf_counter()
        s = self.scenario
        self.record = recorder.record
        rows = Rows(self, outcome)
        try:
            with interrupts.forcible(first=True):  # an FMU's import or __init__ may never return
                self._instantiate(outcome)
                self._initialize()
            self._build_plans()
            self._read_all(s.start)
            self.coupling.set_start_inputs(s.start)
            outcome.init_time = clock.perf_counter() - wall0
            rows.add(s.start)
            with watchdog.armed(s.step_timeout), interrupts.forcible():  # nor a step: the second signal ends it
                self._loop(rows, outcome)
            outcome.loop_time = clock.perf_counter() - wall0 - outcome.init_time
        except SimulationError as exc:
            if interrupts.forced():  # the FMU reported the Interrupted a signal raised in its code
                outcome.status, outcome.stop_reason = Status.INTERRUPTED, f"interrupted by {interrupts.name()}"
            else:
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

    def watches(self):
        """(buffer index, threshold, direction, condition) of every stop condition and range watch."""
        return self.coupling.watches()

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
        coupling = self.coupling
        values, array = coupling.values, coupling.array
        start, h, stop = s.start, s.step, s.stop
        n_steps = max(1, math.ceil((stop - start) / h - 1e-9))
        # an FMU that cannot vary its step gets h for the last one too (stop is start + n h,
        # `capabilities.check_capabilities`), not stop - t, which rounding makes differ from h;
        # the last point recorded is then the time it reached, start + n h
        fixed_only = bool(fixed_step_components(s.system))
        conditions = coupling.watches()
        watched = [idx for idx, *_ in conditions]
        before_values = [values[idx] for idx in watched]  # the watched signals at t
        last_row = bytes(values)  # the whole buffer at t, for an event's interpolation
        coupling.start_stepping()
        advance, extrapolate = coupling.advance, coupling.extrapolate
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
                        fraction = None if threshold is None or coupling.types[cond.signal] != "Real" \
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
