"""Campaign rows on disk: rows.csv appended as runs finish, then sorted rows.csv and rows.parquet.

Numbers are written with repr (shortest exact form), so a row read back is the row written and
a resumed campaign ends with the same files as an uninterrupted one. campaign.json records what
the rows belong to (scenario, seed, runs, dispersions); --resume refuses a different campaign.
"""

import contextlib
import csv
import json
import math
from pathlib import Path

from aotv_cosim.errors import InputError
from aotv_cosim.output.run_files import OutputError, replaced_atomically

TEXT = ("law", "status", "error", "outcome", "outcome.reason")
INTEGER = ("run", "steps")


def csv_cell(name: str, value) -> str:
    """A row value as rows.csv writes it: text as it is, run and steps as integers (empty for
    none), every other number by repr (exact)."""
    if name in TEXT:
        return value
    if name in INTEGER:
        return "" if value is None or (isinstance(value, float) and math.isnan(value)) else str(int(value))
    return repr(float(value))


def _parse(name, text):
    if name in TEXT:
        return text
    if name in INTEGER:
        return int(text) if text else math.nan
    return float(text)


class RowStore:
    """rows.csv of one campaign folder, opened for appending."""

    def __init__(self, out_dir: Path, columns, manifest: dict, resume: bool, units=None):
        """units: {column: unit}, written into rows.parquet's field metadata."""
        self.out = Path(out_dir)
        self.units = units or {}
        self.out.mkdir(parents=True, exist_ok=True)
        self.columns = list(columns)
        self.csv = self.out / "rows.csv"
        self.rows = {}
        manifest_path = self.out / "campaign.json"
        if resume and manifest_path.is_file():
            previous = json.loads(manifest_path.read_text())
            if previous != manifest:
                raise InputError("the folder holds a different campaign", file=manifest_path,
                                 fix="resume with the same scenario, --runs and --seed, or use a new --out")
            self.rows = self._read()
        elif any(self.out.iterdir()) and not resume and self.csv.exists():
            raise InputError("campaign rows already exist", file=self.csv,
                             fix="pass --resume to continue it, or choose another --out")
        elif resume and self.csv.exists():  # rows of an unknown campaign: never overwritten
            raise InputError("cannot resume: rows.csv is here but campaign.json, which says what campaign "
                             "the rows belong to, is not", file=self.csv, entry="--resume",
                             fix="remove rows.csv to start the campaign again, or give a new --out")
        manifest_path.write_text(json.dumps(manifest, indent=2) + "\n")
        self._rewrite(self.rows.values(), self.csv)
        self.file = open(self.csv, "a", newline="")  # noqa: SIM115 - appended run by run; `close` closes it
        self.writer = csv.writer(self.file, lineterminator="\n")

    def _read(self) -> dict:
        """Complete rows of rows.csv by run (a line cut short by a crash is dropped)."""
        if not self.csv.is_file():
            return {}
        rows = {}
        with open(self.csv, newline="") as f:
            text = f.read()
        lines = list(csv.reader(text.splitlines(keepends=True)))
        if lines and lines[0] != self.columns:
            raise InputError("rows.csv has other columns than this scenario gives", file=self.csv,
                             fix="resume with the same scenario, or use a new --out")
        complete = lines[1:] if text.endswith("\n") else lines[1:-1]
        for cells in complete:
            if len(cells) == len(self.columns):
                row = {n: _parse(n, c) for n, c in zip(self.columns, cells)}
                rows[row["run"]] = row
        return rows

    def _rewrite(self, rows, path):
        with replaced_atomically(path) as tmp, open(tmp, "w", newline="") as f:
            writer = csv.writer(f, lineterminator="\n")
            writer.writerow(self.columns)
            for row in rows:
                writer.writerow([csv_cell(n, row[n]) for n in self.columns])

    def done(self) -> set:
        return set(self.rows)

    def add(self, row: dict):
        """Append one finished run (flushed at once: an interruption keeps it)."""
        self.rows[row["run"]] = row
        try:
            self.writer.writerow([csv_cell(n, row[n]) for n in self.columns])
            self.file.flush()
        except OSError as exc:  # a full disk: the rows are kept in memory until then, rows.csv is rewritten whole
            raise OutputError(self.csv, exc) from exc

    def close(self) -> list:
        """Rewrite rows.csv sorted by run, write rows.parquet; returns the sorted rows."""
        with contextlib.suppress(OSError):  # what the last flush could not write is rewritten below
            self.file.close()
        rows = [self.rows[k] for k in sorted(self.rows)]
        self._rewrite(rows, self.csv)
        write_parquet(rows, self.columns, self.out / "rows.parquet", self.units)
        return rows


def write_parquet(rows, columns, path: Path, units=None):
    """rows.parquet; each field's unit (units: {column: unit}) in its metadata under b"unit"."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    units = units or {}
    types = {n: pa.string() if n in TEXT else pa.int64() if n in INTEGER else pa.float64() for n in columns}
    data = {n: [(None if n in INTEGER and isinstance(r[n], float) else r[n]) for r in rows] for n in columns}
    schema = pa.schema([pa.field(n, types[n], metadata={b"unit": units.get(n, "").encode()}) for n in columns])
    table = pa.table({n: pa.array(data[n], type=types[n]) for n in columns}, schema=schema)
    with replaced_atomically(path) as tmp:
        pq.write_table(table, tmp)
