"""Error-controlled stepping: step doubling with FMU state save and restore.

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

The local errors alone do not bound the error at the end on a closed-loop system: an error made
in one state is carried into the others by the following steps. So by default (`check`
"global") each attempt is checked on its global error: the system is run again from the start
with one step over each accepted step and with one over each two (a third and a sixth of the
sweeps, no state saved), and Richardson's extrapolation with the order these three runs show
estimates the attempt's global error (`_global_error`). An attempt above the tolerance is
undone and run again with its tolerances scaled down; the summary's `step_control` gives the
estimate, the observed order, the attempts and the tolerances used.
"""

import itertools
import math
from dataclasses import replace

import numpy as np

from aotv_cosim.simulation import interrupts
from aotv_cosim.errors import SimulationError
from aotv_cosim.simulation.interrupts import Interrupted
from aotv_cosim.simulation.rows import Rows
from aotv_cosim.model.scenario import crossing

EVENT_ITERATIONS = 8
"""Most steps taken to locate a crossing."""


def loop(master, rows, outcome):
    """The error-controlled counterpart of Master._loop: same rows, events and outcome.

    With `check` "global" (the default) each attempt's rows are held back until its global error
    is estimated (`_global_error`); an attempt whose estimate exceeds the tolerance is undone
    (every FMU restored to the start) and run again with tolerances scaled down, at most ATTEMPTS
    times. What an interrupted or failed attempt computed is recorded like any run's rows."""
    control = master.scenario.step_control
    coupling = master.coupling
    stats = outcome.step_control = {"check": control.check, "sweeps": 0}
    step = _stepper(coupling, stats)
    if control.check == "local":
        _attempt(master, rows, outcome, control, step)
        return
    start = coupling.save()
    try:
        asked = control.tolerance
        for attempt in range(1, ATTEMPTS + 1):
            trial, result = _Trial(master, outcome), type(outcome)(step_control={})
            stats["attempts"] = attempt
            estimate = None
            try:
                grid = _attempt(master, trial, result, control, step)
                if result.status == "completed":
                    estimate, order = _global_error(coupling, start, grid, trial, result.event, asked, step)
            except BaseException:
                _adopt(outcome, result, trial, rows, stats)
                raise
            ratio = max(estimate[k] / tol for k, tol in asked.items()) if estimate else 0.0
            if ratio <= 1.0 or attempt == ATTEMPTS:
                break
            factor = RETRY_MARGIN / ratio if math.isfinite(ratio) else UNCHECKED_SHRINK
            control = replace(control, tolerance={k: v * factor for k, v in control.tolerance.items()})
            coupling.restore(start, master.scenario.start)
        _adopt(outcome, result, trial, rows, stats)
        if estimate is not None:
            stats.update(global_error={k: v if math.isfinite(v) else None for k, v in estimate.items()},
                         observed_order=order, tolerance_met=ratio <= 1.0,
                         tolerance_used=dict(control.tolerance))
    finally:
        coupling.free(start)


RETRY_MARGIN = 0.5
"""An attempt retried asks for RETRY_MARGIN * (tolerance / estimated error) of its tolerances:
the global error is about proportional to the tolerance (a local error per unit step), and
the margin covers the departure from it (seed-002 entry with local control, bench/
bench_step_control.py: error / tolerance from 32 to 140 over four tolerances)."""

UNCHECKED_SHRINK = 0.1
"""Tolerance factor of the attempt after one whose coarse runs failed (steps twice and four
times the accepted ones left an FMU's domain): about a third of the steps, with a local error
per unit step O(h^2)."""

ATTEMPTS = 3
"""Most attempts at a tolerance checked on the global error."""


def _stepper(coupling, stats):
    """step(t, dt, earlier, h_earlier): one sweep from t over dt, the delayed inputs extrapolated
    from `earlier`, the buffer h_earlier before t; counted in stats["sweeps"] (every sweep of the
    run: attempts, rejected steps, event location and coarse runs)."""
    coupling.start_stepping()
    advance, extrapolate = coupling.advance, coupling.extrapolate

    def step(t, dt, earlier, h_earlier):
        if extrapolate is not None:
            extrapolate(t, h_earlier, dt, earlier)
        advance(t, dt, t + dt)
        stats["sweeps"] += 1
    return step


class _Trial(Rows):
    """The rows of one attempt, held in memory (no flush) until its global error is known."""

    def keep(self, t, row):
        self.times.append(t)
        self.rows.append(row)


def _adopt(outcome, result, trial, rows, stats):
    """Make attempt `result` the run's outcome and record its rows `trial`."""
    for name in ("status", "stop_reason", "event", "error", "error_detail", "steps"):
        setattr(outcome, name, getattr(result, name))
    stats.update(result.step_control)
    for t, row in zip(trial.times, trial.rows):
        rows.keep(t, row)


def _global_error(coupling, start, grid, trial, event, tolerance, step):
    """({signal: estimated global error}, {signal: observed order}) of the attempt `trial` (its
    rows held back) whose accepted communication points are `grid`.

    The system is run again from `start` twice, one step over each accepted step (coarse) and
    one over each two (coarser). d1 = fine - coarse at every accepted point, d2 = coarse -
    coarser at every other one; at a located event a signal X's difference also carries the
    event's shift, d_X - (dX/dt) / (dS/dt) d_S (S the stop condition's signal, rates from the
    fine run's last two points). The observed order p = log2(max |d2| / max |d1|) over the points
    both have, clipped to [1, 2]: 2 is the order of extrapolated inputs, 1 that of an error made
    where a step straddles a switch (a saturation, a limit). The estimate is Richardson's,
    max |d1| / (2^p - 1). A coarse run that fails (an FMU discards its step) or ends non-finite
    gives an infinite estimate. Afterwards every FMU is back at the attempt's end."""
    end = coupling.save()
    signals = list(tolerance) + ([event["signal"]] if event is not None else [])
    columns = [coupling.index[sig] for sig in signals]
    times = np.array([grid[0], *trial.times])  # the trial's rows start after the start point
    fine = np.frombuffer(start.buffer.tobytes() + b"".join(trial.rows),
                         dtype=np.float64).reshape(len(times), -1)[:, columns]
    coarser_grid = grid[::2] if len(grid) % 2 else [*grid[::2], grid[-1]]
    try:
        with np.errstate(all="ignore"):  # the FMUs' own warnings on a coarse run are not the run's
            coarse = _replay(coupling, start, grid, columns, step)
            coarser = _replay(coupling, start, coarser_grid, columns, step)
    except SimulationError:
        if coupling.broken():
            raise
        return dict.fromkeys(tolerance, math.inf), dict.fromkeys(tolerance)
    finally:
        if not coupling.broken():
            coupling.restore(end, grid[-1])
            coupling.free(end)
    rate = (fine[-1] - fine[-2]) / (times[-1] - times[-2]) if event is not None else None
    d1 = _at_event(fine[np.searchsorted(times, grid)] - coarse, rate)
    shared = np.searchsorted(grid, coarser_grid)
    d2 = _at_event(coarse[shared] - coarser, rate)
    estimates, orders = {}, {}
    for i, sig in enumerate(tolerance):
        whole, on_shared, coarser_diff = (float(np.abs(d[:, i]).max()) for d in (d1, d1[shared], d2))
        ratio = coarser_diff / on_shared if on_shared > 0 else math.inf
        orders[sig] = min(2.0, max(1.0, math.log2(ratio))) if ratio > 0 else 1.0
        estimate = whole / (2.0 ** orders[sig] - 1.0)
        estimates[sig] = estimate if math.isfinite(estimate) else math.inf
    return estimates, orders


def _at_event(difference, rate):
    """Differences of two runs (rows: points; columns: the tolerance signals, then the stop
    signal when `rate` is given), the last row corrected for the event's shift."""
    if rate is not None:
        difference[-1] -= rate / rate[-1] * difference[-1, -1]
    return difference


def _replay(coupling, start, grid, columns, step):
    """The buffer's `columns` at each point of `grid`, stepping from the saved state `start`
    once from each point to the next (inputs extrapolated from the previous point)."""
    array = coupling.array
    coupling.restore(start, grid[0])
    out = np.empty((len(grid), len(columns)))
    out[0] = array[columns]
    earlier, h_earlier = array.copy(), grid[1] - grid[0]
    for k, (a, b) in enumerate(itertools.pairwise(grid), 1):
        before = array.copy()
        step(a, b - a, earlier, h_earlier)
        earlier, h_earlier = before, b - a
        out[k] = array[columns]
    return out


def _attempt(master, rows, outcome, control, step):
    """Step from the start to the stop time or a stop condition under `control`, recording in
    `rows`; returns the accepted communication points (s), the last one an event's time."""
    s = master.scenario
    coupling = master.coupling
    array = coupling.array
    watched = [coupling.index[signal] for signal in control.tolerance]
    conditions = coupling.watches()
    span = s.stop - s.start
    stats = outcome.step_control
    stats.update(accepted=0, rejected=0, kept_at_min=0, smallest=math.inf, largest=0.0)
    t, h = s.start, min(s.step, span)
    grid = [t]
    earlier, h_earlier = array.copy(), h
    try:
        while t < s.stop:
            if interrupts.RECEIVED:
                raise Interrupted(interrupts.name())
            remaining = s.stop - t
            if h >= remaining or remaining - h < control.min:  # no sliver of a last step
                h = remaining
            saved = coupling.save()
            try:
                while True:
                    step(t, h, earlier, h_earlier)
                    full = array[watched].copy()
                    coupling.restore(saved, t)
                    step(t, 0.5 * h, earlier, h_earlier)
                    middle = array.copy()
                    step(t + 0.5 * h, 0.5 * h, saved.buffer, 0.5 * h)
                    ratio = control.error_ratio(full, array[watched], h, span)
                    if ratio <= 1.0 or h <= control.min * (1 + 1e-9):
                        stats["kept_at_min"] += int(ratio > 1.0)
                        break
                    stats["rejected"] += 1
                    coupling.restore(saved, t)
                    h = control.next_step(h, ratio)
                t_end = s.stop if h == remaining else t + h
                points = ((saved.buffer, t, middle, t + 0.5 * h), (middle, t + 0.5 * h, array, t_end))
                for k, (before, t0, after, t1) in enumerate(points):
                    crossing = _first_crossing(conditions, before, after)
                    if crossing is not None:
                        if k:
                            rows.keep(t0, middle.tobytes())
                        grid.append(_locate(master, rows, outcome, crossing, saved, t,
                                            (t0, t1, before, after), step, (earlier, h_earlier),
                                            control))
                        return grid
                rows.keep(t + 0.5 * h, middle.tobytes())
                rows.add(t_end)
                grid.append(t_end)
                stats["accepted"] += 1
                outcome.steps += 2
                stats["smallest"], stats["largest"] = min(stats["smallest"], h), max(stats["largest"], h)
                if master.progress:
                    master.progress(t_end)
            finally:
                coupling.free(saved)
            earlier, h_earlier = middle, 0.5 * h
            t, h = t_end, control.next_step(h, ratio)
        return grid
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
    the buffers there), record that point and end the run there; returns its time (s)."""
    idx, cond, up = crossing
    threshold = cond.threshold
    t0, t1, before, after = bracket
    v0, v1 = float(before[idx]), float(after[idx])
    tolerance = control.tolerance.get(cond.signal, 1e-9 * max(1.0, abs(threshold)))
    side, coupling = 0, master.coupling
    for _ in range(EVENT_ITERATIONS):
        te = t0 + (threshold - v0) / (v1 - v0) * (t1 - t0)
        coupling.restore(saved, t)
        step(t, te - t, *history)
        v = float(coupling.array[idx])
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
    master.stop_at(rows, outcome, cond, up, rows.event(cond, te, te, 1.0, coupling.array))
    rows.add(te)
    outcome.steps += 1
    return te
