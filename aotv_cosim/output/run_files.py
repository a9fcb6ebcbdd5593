"""Result files of one run: timeseries.csv written as the run goes, then summary.json.

The time series is appended chunk by chunk to ``timeseries.csv.part`` and renamed to
``timeseries.csv`` when the run ends, however it ends (completed, failed or interrupted), so a
reader never sees a half-written final file and a failed run keeps every row computed before the
failure. Numbers are written with 17 significant digits: exact, and byte-identical between runs;
Integer and Enumeration columns as integers, Boolean ones as true/false, String ones quoted.
A chunk is written as whole rows; if the write fails (disk full), the file is cut back to its
last whole row and the run fails with an `OutputError` naming the cause.
"""

import contextlib
import io
import json
import os
from functools import partial
from pathlib import Path

import numpy as np

from aotv_cosim.errors import SimulationError


class OutputError(SimulationError):
    """A result file could not be written (disk full, I/O error): the run fails with this cause."""

    def __init__(self, path: Path, exc: OSError):
        super().__init__(f"cannot write {Path(path).name}: {exc.strerror or exc}", file=Path(path).parent,
                         entry="--out", fix="free space on that disk or choose another --out")


def finite_or_text(value):
    """`value` with every float that is not finite (inf, nan; numpy's too) replaced by its text
    ("inf", "-inf", "nan"), inside dicts, lists and tuples: the result files' convention, as JSON
    holds no such number (a campaign's statistics over values near the float range overflow)."""
    if isinstance(value, dict):
        return {k: finite_or_text(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [finite_or_text(v) for v in value]
    if isinstance(value, (float, np.floating)) and not np.isfinite(value):
        return str(float(value))
    return value


@contextlib.contextmanager
def replaced_atomically(path: Path):
    """Yield the temporary file `path`.part to write; it is renamed to `path` when the `with` ends,
    and removed if it raises (a full disk, an interruption): no .part file stays and `path` is the
    whole new file or as it was. An OSError (no space left, file too large) is raised as an
    OutputError naming `path`."""
    path = Path(path)
    tmp = path.with_name(path.name + ".part")
    try:
        yield tmp
        os.replace(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            tmp.unlink(missing_ok=True)
        if isinstance(exc, OSError) and not isinstance(exc, OutputError):
            raise OutputError(path, exc) from exc
        raise


def write_json_atomically(path: Path, data) -> None:
    """Write JSON to path via a temporary file and a rename (`replaced_atomically`; a number that is
    not finite written as its text, `finite_or_text`): on failure neither a temporary file nor a
    changed `path`, and an OutputError."""
    text = json.dumps(finite_or_text(data), indent=2, allow_nan=False, default=float) + "\n"
    with replaced_atomically(path) as tmp, open(tmp, "w") as f:
        f.write(text)


class TimeSeriesWriter:
    """Receives chunks (times, rows of the master's buffer) and appends the chosen columns;
    `decoder` (`variable_types.Decoder`) types the columns that are not Real."""

    def __init__(self, out_dir: Path, columns, index, decoder=None):
        self.path = Path(out_dir) / "timeseries.csv"
        self.part = self.path.with_name("timeseries.csv.part")
        self.columns = list(columns)
        self.select = [index[c] for c in self.columns]
        self.decoder = decoder if decoder is not None and any(
            decoder.kind(c) != "Real" for c in self.columns) else None
        self.times: list[np.ndarray] = []
        self.chunks: list[np.ndarray] = []
        self.whole = 0  # bytes of the file that are whole lines (header and rows)
        try:
            self.file = open(self.part, "wb", buffering=0)  # noqa: SIM115 - written row by row; `close` closes it
        except OSError as exc:
            raise OutputError(self.part, exc) from exc
        self._write((",".join(["time", *self.columns]) + "\n").encode())

    def _write(self, data: bytes):
        """Append whole lines; on failure cut the file back to its last whole line (and go on
        from there), raise OutputError. An interruption raised between two partial writes
        (`interrupts.forcible`) cuts it back too, so the rows written after it stay whole lines."""
        try:
            view = memoryview(data)
            while view:
                view = view[self.file.write(view):]
        except BaseException as exc:
            with contextlib.suppress(OSError):
                self.file.truncate(self.whole)
                self.file.seek(self.whole)
            if isinstance(exc, OSError):
                raise OutputError(self.part, exc) from exc
            raise
        self.whole += len(data)

    def __call__(self, times, rows):
        data = np.column_stack([times, rows[:, self.select]])
        text = io.StringIO()
        if self.decoder is None:
            np.savetxt(text, data, fmt="%.17g", delimiter=",")
        else:
            _typed_lines(text, data, ["Real"] + [self.decoder.kind(c) for c in self.columns], self.decoder.texts)
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


def _typed_lines(text, data, kinds, texts):
    """Rows of `data` (time first) as CSV lines, each column written as its type: Real with 17
    significant digits, Integer and Enumeration as integers, Boolean as true/false, String
    quoted (a quote doubled)."""
    def cell(kind, x):
        if kind == "Real":
            return f"{x:.17g}"
        if kind == "Boolean":
            return "true" if x else "false"
        if kind == "String":
            return '"' + texts[int(x)].replace('"', '""') + '"'
        return "%d" % x  # noqa: UP031 - %d takes the float the row holds, format spec d refuses it
    for row in data:
        text.write(",".join(cell(k, x) for k, x in zip(kinds, row)) + "\n")


def statistics(columns, times, rows, decoder=None):
    """Final values, minima and maxima (with their times) of each column; with a `decoder` the
    columns that are not Real are given as their type (no extrema for a String)."""
    final: dict[str, object] = {}
    minima: dict[str, dict] = {}
    maxima: dict[str, dict] = {}
    if len(times) == 0:
        return final, minima, maxima
    for k, name in enumerate(columns):
        col = rows[:, k]
        kind = decoder.kind(name) if decoder is not None else "Real"
        finite = np.isfinite(col)
        final[name] = _number(col[-1]) if kind == "Real" else decoder.value(name, col[-1])
        if finite.any() and kind != "String":
            i_min = int(np.nanargmin(np.where(finite, col, np.nan)))
            i_max = int(np.nanargmax(np.where(finite, col, np.nan)))
            value = float if kind == "Real" else partial(decoder.value, name)
            minima[name] = {"value": value(col[i_min]), "time": float(times[i_min])}
            maxima[name] = {"value": value(col[i_max]), "time": float(times[i_max])}
    return final, minima, maxima


def _number(x):
    x = float(x)
    return x if np.isfinite(x) else str(x)


def evaluate_expectations(expectations, columns, times, rows, event, decoder=None):
    """Measured value, error and pass/fail of each expectation: a Real or Integer one within its
    allowed error (an Integer without tolerance exactly), a Boolean, String or Enumeration one
    by equality (`error` and `allowed_error` None)."""
    results = []
    for e in expectations:
        kind = decoder.kind(e.signal) if decoder is not None else "Real"
        measured = _measure(e, columns, times, rows, event, kind)
        if kind in ("Real", "Integer"):
            error = None if measured is None else measured - e.value
            allowed = e.allowed_error()
            passed = error is not None and bool(np.isfinite(error)) and abs(error) <= allowed
        else:
            measured = None if measured is None else decoder.value(e.signal, measured) \
                if not isinstance(measured, str) else measured
            error = allowed = None
            passed = measured is not None and measured == e.value
        results.append({
            "signal": e.signal, "at": e.at, "expected": e.value, "measured": measured,
            "error": error, "allowed_error": allowed, "source": e.source, "note": e.note,
            "passed": passed,
        })
    return results


def _measure(e, columns, times, rows, event, kind="Real"):
    """The value `e` checks, as a float; a discrete signal's value at a time is the one it
    holds there (its last value at or before that time), not an interpolation."""
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
        return None if event is None else event["values"][e.signal]
    if not times[0] <= e.at <= times[-1]:
        return None
    if kind != "Real":
        return float(col[int(np.searchsorted(times, e.at, side="right")) - 1])
    return float(np.interp(e.at, times, col))
