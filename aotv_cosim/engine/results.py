"""Result files of one run: timeseries.csv written as the run goes, then summary.json.

The time series is appended chunk by chunk to ``timeseries.csv.part`` and renamed to
``timeseries.csv`` when the run ends, however it ends (completed, failed or interrupted), so a
reader never sees a half-written final file and a failed run keeps every row computed before the
failure. Numbers are written with 17 significant digits: exact, and byte-identical between runs.
A chunk is written as whole rows; if the write fails (disk full), the file is cut back to its
last whole row and the run fails with an `OutputError` naming the cause.
"""

import io
import json
import os
from pathlib import Path

import numpy as np

from aotv_cosim.engine.errors import SimulationError


class OutputError(SimulationError):
    """A result file could not be written (disk full, I/O error): the run fails with this cause."""

    component = variable = time = None

    def __init__(self, path: Path, exc: OSError):
        super().__init__(f"cannot write {Path(path).name}: {exc.strerror or exc}", file=Path(path).parent,
                         entry="--out", fix="free space on that disk or choose another --out")


def write_json_atomically(path: Path, data) -> None:
    """Write JSON to path via a temporary file and a rename; on failure leave neither a
    temporary file nor a changed `path`, and raise OutputError."""
    tmp = path.with_name(path.name + ".part")
    try:
        with open(tmp, "w") as f:
            f.write(json.dumps(data, indent=2, allow_nan=False, default=float) + "\n")
        os.replace(tmp, path)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        raise OutputError(path, exc) from exc


class TimeSeriesWriter:
    """Receives chunks (times, rows of the master's buffer) and appends the chosen columns."""

    def __init__(self, out_dir: Path, columns, index):
        self.path = Path(out_dir) / "timeseries.csv"
        self.part = self.path.with_name("timeseries.csv.part")
        self.columns = list(columns)
        self.select = [index[c] for c in self.columns]
        self.times, self.chunks = [], []
        self.whole = 0  # bytes of the file that are whole lines (header and rows)
        try:
            self.file = open(self.part, "wb", buffering=0)
        except OSError as exc:
            raise OutputError(self.part, exc) from exc
        self._write((",".join(["time"] + self.columns) + "\n").encode())

    def _write(self, data: bytes):
        """Append whole lines; on failure cut the file back to its last whole line, raise OutputError."""
        try:
            view = memoryview(data)
            while view:
                view = view[self.file.write(view):]
        except OSError as exc:
            try:
                self.file.truncate(self.whole)
            except OSError:
                pass
            raise OutputError(self.part, exc) from exc
        self.whole += len(data)

    def __call__(self, times, rows):
        data = np.column_stack([times, rows[:, self.select]])
        text = io.StringIO()
        np.savetxt(text, data, fmt="%.17g", delimiter=",")
        self._write(text.getvalue().encode())
        self.times.append(times)
        self.chunks.append(data[:, 1:])

    def close(self):
        """Close and rename to timeseries.csv; raises OutputError if the rename fails."""
        self.file.close()
        try:
            os.replace(self.part, self.path)
        except OSError as exc:
            raise OutputError(self.path, exc) from exc

    def table(self):
        """(times, rows) of everything written so far."""
        if not self.chunks:
            return np.empty(0), np.empty((0, len(self.columns)))
        return np.concatenate(self.times), np.vstack(self.chunks)


def statistics(columns, times, rows):
    """Final values, minima and maxima (with their times) of each column."""
    final, minima, maxima = {}, {}, {}
    if len(times) == 0:
        return final, minima, maxima
    for k, name in enumerate(columns):
        col = rows[:, k]
        finite = np.isfinite(col)
        final[name] = _number(col[-1])
        if finite.any():
            i_min = int(np.nanargmin(np.where(finite, col, np.nan)))
            i_max = int(np.nanargmax(np.where(finite, col, np.nan)))
            minima[name] = {"value": float(col[i_min]), "time": float(times[i_min])}
            maxima[name] = {"value": float(col[i_max]), "time": float(times[i_max])}
    return final, minima, maxima


def _number(x):
    x = float(x)
    return x if np.isfinite(x) else str(x)


def evaluate_expectations(expectations, columns, times, rows, event):
    """Measured value, error and pass/fail of each expectation."""
    results = []
    for e in expectations:
        measured = _measure(e, columns, times, rows, event)
        error = None if measured is None else measured - e.value
        allowed = e.allowed_error()
        results.append({
            "signal": e.signal, "at": e.at, "expected": e.value, "measured": measured,
            "error": error, "allowed_error": allowed, "source": e.source, "note": e.note,
            "passed": error is not None and bool(np.isfinite(error)) and abs(error) <= allowed,
        })
    return results


def _measure(e, columns, times, rows, event):
    if len(times) == 0:
        return None
    col = rows[:, columns.index(e.signal)]
    if e.at == "end":
        return float(col[-1])
    if e.at == "min":
        return float(np.min(col))
    if e.at == "max":
        return float(np.max(col))
    if e.at == "event":
        return None if event is None else float(event["values"][e.signal])
    if not times[0] <= e.at <= times[-1]:
        return None
    return float(np.interp(e.at, times, col))
