"""Recorded communication points of a run: kept as the bytes of the master's value buffer and
flushed in chunks to the run's `Recorder`, with the first non-finite value found per chunk and
blamed on the component that produced it.
"""

from typing import Protocol

import numpy as np

from aotv_cosim.errors import SimulationError
from aotv_cosim.model.variable_types import typed

CHUNK = 1000
"""Communication points recorded between two flushes to the result files."""


class Recorder(Protocol):
    """What `Master.run` passes the recorded rows to."""

    def record(self, times: np.ndarray, rows: np.ndarray) -> None:
        """A chunk of recorded communication points: their times (s) and the master's value
        buffer at each (float64, one column per signal as `Master.index` lays them out)."""


class Rows:
    """Recorded communication points flushed in chunks to `master.record` (the run's `Recorder`).

    A row is kept as the bytes of the master's value buffer (one memcpy), made an array of rows
    when the chunk is flushed."""

    def __init__(self, master, outcome):
        self.master = master
        self.outcome = outcome
        self.times, self.rows = [], []

    def add(self, t):
        """Record the communication point t now (the loop itself records every n-th step)."""
        self.keep(t, bytes(self.master.coupling.values))

    def keep(self, t, row):
        """Record the communication point t with `row`, the bytes of the buffer there."""
        self.times.append(t)
        self.rows.append(row)
        if len(self.rows) >= CHUNK:
            self.flush()

    def flush(self):
        """Pass the kept rows on; a time without its row (a KeyboardInterrupt raised between the
        two appends, when signals are not deferred) is dropped, so times and rows always pair."""
        n = min(len(self.times), len(self.rows))
        del self.times[n:], self.rows[n:]
        if not n:
            return
        width = len(self.master.coupling.array)
        rows = np.frombuffer(b"".join(self.rows), dtype=np.float64).reshape(n, -1)[:, :width]
        times = np.array(self.times)
        self.times.clear()
        self.rows.clear()
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
        return SimulationError(f"output {var} is not finite at t = {t:.6g} s",
                               file=inst.info.path.name, entry=signal,
                               fix="check the inputs and parameters of this component",
                               component=comp, variable=var, time=float(t))

    def event(self, cond, t0, t1, fraction, previous):
        """The stop condition's crossing, linearly interpolated between two communication points
        (`fraction` None for a discrete signal: the values at t1), each value of its type."""
        if fraction is None:
            fraction, values = 1.0, self.master.coupling.array
        else:
            values = previous + fraction * (self.master.coupling.array - previous)
        kinds, strings = self.master.coupling.types, self.master.strings
        return {"signal": cond.signal, "threshold": cond.threshold, "time": t0 + fraction * (t1 - t0),
                "values": {sig: float(values[i]) if kinds[sig] == "Real" else typed(kinds[sig], values[i], strings)
                           for sig, i in self.master.index.items()}}
