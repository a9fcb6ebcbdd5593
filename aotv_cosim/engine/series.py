"""A run's recorded time series in memory, its units, and its Parquet file.

`SeriesTable` is the master's `record` callback of a run that writes nothing while it runs (the
Python API's `run(out=None)`, or `--format parquet`); it offers the same `close` and `table` as
`results.TimeSeriesWriter`. `units_of` gives each column's unit as the FMU's modelDescription
declares it (SI, "1" for dimensionless, "" when an FMU declares none). `write_parquet` writes
time and columns as float64 fields, each field's unit in its metadata under b"unit".
"""

import os
from pathlib import Path

import numpy as np

TIME_UNIT = "s"
"""Unit of the time column (the FMI communication time is in seconds)."""


class SeriesTable:
    """Keeps the chosen columns of the recorded chunks (times, rows of the master's buffer)."""

    def __init__(self, columns, index):
        self.columns = list(columns)
        self.select = [index[c] for c in self.columns]
        self.times, self.chunks = [], []

    def __call__(self, times, rows):
        self.times.append(np.array(times, dtype=float))
        self.chunks.append(np.array(rows[:, self.select], dtype=float))

    def close(self):
        """Nothing to release: the rows stay in memory."""

    def table(self):
        """(times, rows) of everything recorded."""
        if not self.chunks:
            return np.empty(0), np.empty((0, len(self.columns)))
        return np.concatenate(self.times), np.vstack(self.chunks)


def units_of(system, columns) -> dict:
    """{"time": "s", column: declared unit} for the signals 'component.variable' of `system`."""
    return {"time": TIME_UNIT, **{c: system.variable(c).unit for c in columns}}


def write_parquet(path, columns, times, rows, units) -> Path:
    """Write time and the columns to the Parquet file `path` (via a temporary file and a rename),
    with each field's unit in its metadata (b"unit") and the units also in the schema metadata
    (b"units", JSON), so a reader sees them with or without per-field support."""
    import json

    import pyarrow as pa
    import pyarrow.parquet as pq

    path = Path(path)
    names = ["time"] + list(columns)
    data = [np.asarray(times, dtype=float)] + [np.asarray(rows[:, k], dtype=float) for k in range(len(columns))]
    fields = [pa.field(n, pa.float64(), metadata={b"unit": units.get(n, "").encode()}) for n in names]
    schema = pa.schema(fields, metadata={b"units": json.dumps({n: units.get(n, "") for n in names}).encode()})
    table = pa.Table.from_arrays([pa.array(d) for d in data], schema=schema)
    tmp = path.with_name(path.name + ".part")
    pq.write_table(table, tmp)
    os.replace(tmp, path)
    return path
