"""A run's recorded time series in memory, its units, and its Parquet file.

`SeriesTable` is the master's `record` callback of a run that writes nothing while it runs (the
Python API's `run(out=None)`, or `--format parquet`); it offers the same `close` and `table` as
`results.TimeSeriesWriter`. `units_of` gives each column's unit as the FMU's modelDescription
declares it (SI, "1" for dimensionless, "" when an FMU declares none). `write_parquet` writes
time and Real columns as float64 fields, Integer and Enumeration ones as int32 (int64 when a value
needs it: an FMI 3.0 UInt32, Int64, UInt64), Boolean ones as
bool and String ones as string, each field's unit in its metadata under b"unit".
"""

import os
from pathlib import Path

import numpy as np

TIME_UNIT = "s"
"""Unit of the time column (the FMI communication time is in seconds)."""


class SeriesTable:
    """Keeps the chosen columns of the recorded chunks (times, rows of the master's buffer)."""

    def __init__(self, columns, index, decoder=None):
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


def write_parquet(path, columns, times, rows, units, decoder=None) -> Path:
    """Write time and the columns to the Parquet file `path` (via a temporary file and a rename),
    with each field's unit in its metadata (b"unit") and the units also in the schema metadata
    (b"units", JSON), so a reader sees them with or without per-field support; `decoder`
    (`variable_types.Decoder`) gives the columns that are not Real their types."""
    import json

    import pyarrow as pa
    import pyarrow.parquet as pq

    path = Path(path)
    names = ["time", *columns]
    data = [np.asarray(times, dtype=float)] + [
        np.asarray(rows[:, k], dtype=float) if decoder is None else decoder.column(c, rows[:, k])
        for k, c in enumerate(columns)]
    kinds = ["Real"] + [decoder.kind(c) if decoder is not None else "Real" for c in columns]
    arrow = {"Real": pa.float64(), "Integer": pa.int32(), "Enumeration": pa.int32(), "Boolean": pa.bool_(),
             "String": pa.string()}
    fields = [pa.field(n, pa.from_numpy_dtype(d.dtype) if k in ("Integer", "Enumeration") else arrow[k],
                       metadata={b"unit": units.get(n, "").encode()}) for n, k, d in zip(names, kinds, data)]
    schema = pa.schema(fields, metadata={b"units": json.dumps({n: units.get(n, "") for n in names}).encode()})
    table = pa.Table.from_arrays([pa.array(d, type=f.type) for d, f in zip(data, fields)], schema=schema)
    tmp = path.with_name(path.name + ".part")
    pq.write_table(table, tmp)
    os.replace(tmp, path)
    return path
