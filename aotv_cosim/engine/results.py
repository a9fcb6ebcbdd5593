"""Result files of one run: timeseries.csv written as the run goes, then summary.json.

The time series is appended chunk by chunk to ``timeseries.csv.part`` and renamed to
``timeseries.csv`` when the run ends, however it ends (completed, failed or interrupted), so a
reader never sees a half-written final file and a failed run keeps every row computed before the
failure. Numbers are written with 17 significant digits: exact, and byte-identical between runs.
"""

import json
import os
from pathlib import Path

import numpy as np


def write_json_atomically(path: Path, data) -> None:
    """Write JSON to path via a temporary file and a rename."""
    tmp = path.with_name(path.name + ".part")
    tmp.write_text(json.dumps(data, indent=2, allow_nan=False, default=float) + "\n")
    os.replace(tmp, path)


class TimeSeriesWriter:
    """Receives chunks (times, rows of the master's buffer) and appends the chosen columns."""

    def __init__(self, out_dir: Path, columns, index):
        self.path = Path(out_dir) / "timeseries.csv"
        self.part = self.path.with_name("timeseries.csv.part")
        self.columns = list(columns)
        self.select = [index[c] for c in self.columns]
        self.times, self.chunks = [], []
        self.file = open(self.part, "w", newline="\n")
        self.file.write(",".join(["time"] + self.columns) + "\n")
        self.file.flush()

    def __call__(self, times, rows):
        data = np.column_stack([times, rows[:, self.select]])
        np.savetxt(self.file, data, fmt="%.17g", delimiter=",")
        self.file.flush()
        self.times.append(times)
        self.chunks.append(data[:, 1:])

    def close(self):
        self.file.close()
        os.replace(self.part, self.path)

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
