"""Error-controlled stepping: step doubling with FMU state save and restore (issue 17 item 4).

From a communication point t the loop saves every FMU's state (fmi2GetFMUstate) and the master's
buffer, takes one step of h, restores, and takes two steps of h/2. The difference of the two
results in the tolerance signals estimates the local coupling error of the two halves
(`StepControl.error_ratio`); within the budget the halves are kept (both points recorded),
otherwise the state is restored and a shorter step tried (`StepControl.next_step`). A step at the
`min` bound is kept whatever its error, and counted.

Stop conditions and range watches are checked at both half points. A crossing is located on a
real state, not interpolated: from the state saved at t the loop steps straight to the
interpolated crossing time and repeats (regula falsi, Illinois) until the signal is within
its tolerance of the threshold (1e-9 of the threshold's size for a signal without one), so the
event row is a communication point the FMUs computed.
"""

import math

from aotv_cosim.engine import interrupts
from aotv_cosim.engine.interrupts import Interrupted
from aotv_cosim.engine.scenario import crossing

EVENT_ITERATIONS = 8
"""Most steps taken to locate a crossing."""


class _Saved:
    """Every FMU's state and the master's buffer at one communication point."""

    def __init__(self, master):
        self.instances = list(master.instances.values())
        self.handles = [inst.save_state() for inst in self.instances]
        self.buffer = master.array.copy()

    def restore(self, master, t):
        for inst, handle in zip(self.instances, self.handles):
            inst.restore_state(handle, t)
        master.array[:] = self.buffer

    def free(self):
        """Free the states, except on an instance that failed (`FmuInstance.close` says why)."""
        for inst, handle in zip(self.instances, self.handles):
            if not inst.broken:
                inst.free_state(handle)


def loop(master, rows, outcome):
    """The error-controlled counterpart of Master._loop: same rows, events and outcome."""
    s = master.scenario
    control = s.step_control
    array = master.array
    finish, extrapolate = master._end_of_sweep()
    advance = master.sweeper(finish)
    watched = [master.index[signal] for signal in control.tolerance]
    conditions = master.watches()
    span = s.stop - s.start
    stats = outcome.step_control = {"accepted": 0, "rejected": 0, "kept_at_min": 0, "sweeps": 0,
                                    "smallest": math.inf, "largest": 0.0}

    def step(t, dt, earlier, h_earlier):
        """One sweep from t over dt; `earlier`: the buffer h_earlier before t (extrapolation)."""
        if extrapolate is not None:
            extrapolate(t, h_earlier, dt, earlier)
        advance(t, dt, t + dt)
        stats["sweeps"] += 1

    t, h = s.start, min(s.step, span)
    earlier, h_earlier = array.copy(), h
    try:
        while t < s.stop:
            if interrupts.RECEIVED:
                raise Interrupted(interrupts.name())
            remaining = s.stop - t
            if h >= remaining or remaining - h < control.min:  # no sliver of a last step
                h = remaining
            saved = _Saved(master)
            try:
                while True:
                    step(t, h, earlier, h_earlier)
                    full = array[watched].copy()
                    saved.restore(master, t)
                    step(t, 0.5 * h, earlier, h_earlier)
                    middle = array.copy()
                    step(t + 0.5 * h, 0.5 * h, saved.buffer, 0.5 * h)
                    ratio = control.error_ratio(full, array[watched], h, span)
                    if ratio <= 1.0 or h <= control.min * (1 + 1e-9):
                        stats["kept_at_min"] += int(ratio > 1.0)
                        break
                    stats["rejected"] += 1
                    saved.restore(master, t)
                    h = control.next_step(h, ratio)
                t_end = s.stop if h == remaining else t + h
                points = ((saved.buffer, t, middle, t + 0.5 * h), (middle, t + 0.5 * h, array, t_end))
                for k, (before, t0, after, t1) in enumerate(points):
                    crossing = _first_crossing(conditions, before, after)
                    if crossing is not None:
                        if k:
                            rows.keep(t0, middle.tobytes())
                        _locate(master, rows, outcome, crossing, saved, t, (t0, t1, before, after),
                                step, (earlier, h_earlier), control)
                        return
                rows.keep(t + 0.5 * h, middle.tobytes())
                rows.add(t_end)
                stats["accepted"] += 1
                outcome.steps += 2
                stats["smallest"], stats["largest"] = min(stats["smallest"], h), max(stats["largest"], h)
                if master.progress:
                    master.progress(t_end)
            finally:
                saved.free()
            earlier, h_earlier = middle, 0.5 * h
            t, h = t_end, control.next_step(h, ratio)
    finally:
        if not math.isfinite(stats["smallest"]):
            stats["smallest"] = None


def _first_crossing(conditions, before, after):
    """(condition, up) of the first stop condition crossed from buffer `before` to `after`."""
    for idx, threshold, direction, cond in conditions:
        up = crossing(before[idx], after[idx], threshold, direction)
        if up is not None:
            return idx, cond, up
    return None


def _locate(master, rows, outcome, crossing, saved, t, bracket, step, history, control):
    """Step from the state saved at t to the crossing of `crossing` inside `bracket` (t0, t1 and
    the buffers there), record that point and end the run there."""
    idx, cond, up = crossing
    threshold = cond.threshold
    t0, t1, before, after = bracket
    v0, v1 = float(before[idx]), float(after[idx])
    tolerance = control.tolerance.get(cond.signal, 1e-9 * max(1.0, abs(threshold)))
    side = 0
    for _ in range(EVENT_ITERATIONS):
        te = t0 + (threshold - v0) / (v1 - v0) * (t1 - t0)
        saved.restore(master, t)
        step(t, te - t, *history)
        v = float(master.array[idx])
        if abs(v - threshold) <= tolerance:
            break
        if (v - threshold) * (v0 - threshold) > 0:  # still before the crossing
            t0, v0 = te, v
            v1 = v1 if side != -1 else threshold + 0.5 * (v1 - threshold)  # Illinois
            side = -1
        else:
            t1, v1 = te, v
            v0 = v0 if side != 1 else threshold + 0.5 * (v0 - threshold)
            side = 1
    master.stop_at(rows, outcome, cond, up, rows.event(cond, te, te, 1.0, master.array))
    rows.add(te)
    outcome.steps += 1
