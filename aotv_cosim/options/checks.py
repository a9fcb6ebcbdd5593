"""Every option value of every command checked here, once, whichever face gave it (the command line
or the Python API): type, range, finiteness, counts and paths. A refused value is an `InputError`
whose line is `FILE: ENTRY: CAUSE; FIX`, FILE the command's scenario (or set, or source) and ENTRY
the option as the command line spells it (`--runs`), so both faces print and raise the same line.

An options class (`options.commands`) declares each field with `field(default=..., metadata=rule(check,
entry))`;
`Options.__post_init__` runs the checks in field order, stores what they return (a path as a
`Path`, a mapping as a tuple of pairs, so the object stays frozen and hashable) and then the
class's `_check_together` for rules between fields.
"""

import math
import numbers
import os
import re
from collections.abc import Callable, Mapping
from collections.abc import Set as AbstractSet
from dataclasses import fields
from pathlib import Path
from typing import Any, ClassVar, TypeVar

from aotv_cosim.errors import InputError

MAX_RUNS = 1_000_000
"""Most runs of one campaign (per law in a benchmark). Every row is kept in memory for the
statistics and the report (8.5 kB for the 74 values of an aerocapture row), and 10^6 runs are
already hours of a cluster; a larger N is a typing error (`benchmark --runs 1000000000` grew to
6 GB before this bound). `check_fits` also refuses a smaller N whose rows cannot fit in this
machine's memory."""
MAX_SEED = 2**63 - 1
"""Largest campaign seed (numpy's SeedSequence takes any non-negative integer; this bound keeps
the seed in a signed 64-bit column of the result files)."""
WORKERS_PER_CORE = 4
"""Most local worker processes per usable core: more only compete for the cores, and each holds
its own FMU instances (150-250 MiB)."""
MAX_SCHEDULED_WORKERS = 4096
"""Most workers a Dask campaign is told to plan batches for."""
MAX_POINTS = 100_000
"""Most grid points one sweep flies: above, a typo (an extra zero in N) would start a sweep of
days and allocate every point up front, so it is refused before any run."""
ROW_CELL_BYTES = 120
"""Memory of one value of a campaign row as the parent holds it, bytes: a row of the aerocapture
benchmark (74 values) unpickled from a worker took 8455 bytes (114 a value: the dict's slot, the
float and the key's own string; tracemalloc over 2000 rows)."""


def usable_cores() -> int:
    """The cores this process may run on (its CPU affinity where the OS has one)."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def named(value):
    """The FILE an option's error line names for the value given as the command's file (a path, or
    a loaded scenario's path); None for a value that is no path."""
    value = getattr(value, "path", value)
    return value if isinstance(value, (str, os.PathLike)) and not isinstance(value, bytes) else None


class Where:
    """The FILE and ENTRY of a refused value."""

    def __init__(self, file, entry):
        self.file, self.entry = file, entry

    def refuse(self, cause, fix) -> InputError:
        return InputError(cause, file=self.file, entry=self.entry, fix=fix)


def rule(check: Callable, entry: str) -> dict:
    """The metadata of a dataclass field whose value `check(value, where)` checks and normalises
    (`Where` gives the line's FILE and ENTRY, `entry` as the command line names the option):
    `field(default=..., metadata=rule(check, "--option"))`."""
    return {"check": check, "entry": entry}


_O = TypeVar("_O", bound="Options")


class Options:
    """Base of the frozen options classes: checks every field on construction (module docstring)."""

    __dataclass_fields__: ClassVar[dict[str, Any]]  # every subclass is a dataclass

    @classmethod
    def of(cls: type[_O], **raw: Any) -> _O:
        """The options made of a face's raw values (a str path, a dict of overrides, ...): the
        fields' annotations give the types the checks convert them to on construction."""
        return cls(**raw)

    def __post_init__(self):
        for f in fields(self):
            check = f.metadata.get("check")
            if check is not None:
                value = check(getattr(self, f.name), Where(self._file(), f.metadata["entry"]))
                object.__setattr__(self, f.name, value)
        self._check_together()

    def _file(self):
        """The FILE of this command's error lines (its scenario, set or source); None if none."""

    def _check_together(self) -> None:
        """Rules between fields (none by default)."""

    def replace(self, **changes):
        """A copy with `changes`, checked again."""
        import dataclasses

        return dataclasses.replace(self, **changes)


def _shown(value) -> str:
    """A refused value in a message: its repr, cut, and its type when that is the point."""
    text = repr(value)
    text = text if len(text) <= 60 else text[:57] + "..."
    return f"{text} ({type(value).__name__})"


def _is_number(value) -> bool:
    """A real number (int, float, or numpy's scalars of them), not a bool."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def _is_integer(value) -> bool:
    """An integer (int, or numpy's integer scalars), not a bool."""
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)


def _as_float(value):
    """`value` (a real number) as a float; None for an integer beyond the float range."""
    try:
        return float(value)
    except OverflowError:
        return None


def count(low: int, high, what: str, fix: str = "") -> Callable:
    """An integer from `low` to `high` (a callable giving the bound when it depends on the
    machine), returned as an int (numpy's integers too); a bool, a float or text is refused."""
    def check(value, where: Where):
        top = high() if callable(high) else high
        if not _is_integer(value):
            raise where.refuse(f"{what} must be an integer, got {_shown(value)}",
                               f"give an integer from {low} to {top}")
        value = int(value)
        if not low <= value <= top:
            raise where.refuse(f"{what} {value} is outside {low}..{top}", fix or f"give an integer from {low} to {top}")
        return value
    return check


def workers(value, where: Where):
    """Workers: None (every usable core) or an integer from 1 to MAX_SCHEDULED_WORKERS (local
    processes are bounded further by `local_workers`)."""
    if value is None:
        return usable_cores()
    return count(1, MAX_SCHEDULED_WORKERS, "workers")(value, where)


def local_workers(value: object, where: Where) -> int:
    """Local worker processes: at most WORKERS_PER_CORE x the usable cores."""
    return count(1, WORKERS_PER_CORE * usable_cores(), "workers",
                 f"give at most {WORKERS_PER_CORE} per usable core ({usable_cores()} here); more only compete "
                 "for the cores and memory")(value, where)


def number(*, low=-math.inf, high=math.inf, low_open=False, optional=False, unit="", what="the value") -> Callable:
    """A finite real number in [low, high] (`low_open`: above low), as a float; None when `optional`."""
    def check(value, where: Where):
        if value is None and optional:
            return None
        bounds = f"{'above' if low_open else 'at least'} {low:g}" if low > -math.inf else ""
        bounds += (" and " if bounds else "") + f"at most {high:g}" if high < math.inf else ""
        fix = f"give a finite number{' ' + bounds if bounds else ''}{' in ' + unit if unit else ''}" + \
            (" (or leave it out)" if optional else "")
        if not _is_number(value):
            raise where.refuse(f"{what} must be a number, got {_shown(value)}", fix)
        number = _as_float(value)
        if number is None or not math.isfinite(number) or number < low or (low_open and number == low) \
                or number > high:
            shown = repr(number) if number is not None else _shown(value)
            raise where.refuse(f"{what} {shown}{' ' + unit if unit else ''} is not a finite number "
                               f"{bounds}".rstrip(), fix)
        return number
    return check


def step_limit(value, where: Where):
    """A step's wall-clock limit, s: None (not given) or a finite number of at least
    `watchdog.MIN_STEP_TIMEOUT` (a smaller one could not be met: the watchdog would not see it)."""
    from aotv_cosim.simulation.watchdog import MIN_STEP_TIMEOUT

    return number(low=MIN_STEP_TIMEOUT, optional=True, unit="s", what="the time limit")(value, where)


MIN_MAX_RSS_MIB = 64.0
"""Smallest memory limit of a worker, MiB: a worker forked from the command line holds about 80 MiB
(Python, numpy, scipy; 77 MiB measured) before its first FMU, so a smaller limit fails every run:
`--max-rss 2` meant for 2 GiB is refused, not flown."""


def memory_limit(value, where: Where):
    """A worker's resident memory limit, MiB: None (no limit) or a finite number of at least
    MIN_MAX_RSS_MIB."""
    return number(low=MIN_MAX_RSS_MIB, optional=True, unit="MiB", what="the memory limit")(value, where)


def flag(value, where: Where) -> bool:
    """True or False (numpy's too; not 1, not "yes")."""
    if type(value).__module__ == "numpy" and type(value).__name__ == "bool_":
        value = bool(value)
    if not isinstance(value, bool):
        raise where.refuse(f"expected True or False, got {_shown(value)}", "give True or False")
    return value


def choice(*allowed, optional=False) -> Callable:
    """One of `allowed` (None too when `optional`)."""
    def check(value, where: Where):
        if (value is None and optional) or (value in allowed and type(value) is type(allowed[0])):
            return value
        raise where.refuse(f"unknown value {_shown(value)}", f"give {' or '.join(map(repr, allowed))}")
    return check


def path(what: str, optional=False) -> Callable:
    """A file or folder path (str or os.PathLike, no NUL byte) as a Path; None when `optional`.
    Whether it exists is the loader's to say (with the file's own message)."""
    def check(value, where: Where):
        if value is None and optional:
            return None
        if isinstance(value, bytes) or not isinstance(value, (str, os.PathLike)):
            raise where.refuse(f"expected the path of {what}, got {_shown(value)}", f"give the path of {what}")
        text = os.fspath(value)
        if not isinstance(text, str) or not text or "\0" in text:
            raise where.refuse(f"not a usable path: {text!r}", f"give the path of {what} (no NUL byte)")
        return Path(text)
    return check


def existing_file(what: str) -> Callable:
    """A path (`path`) of an existing regular file."""
    from aotv_cosim.paths import regular_file

    def check(value, where: Where):
        value = path(what)(value, where)
        try:
            regular_file(value, what=what)
        except InputError as exc:
            raise InputError(exc.cause, file=value, entry=where.entry, fix=exc.fix) from None
        return value
    return check


def paths(what: str) -> Callable:
    """Paths (`path`) as a tuple: an iterable of them, or one path given alone (a str is one path,
    never read letter by letter)."""
    def check(value, where: Where):
        if value is None:
            return ()
        if isinstance(value, (str, os.PathLike)):
            value = [value]
        if isinstance(value, (bytes, dict)) or not hasattr(value, "__iter__"):
            raise where.refuse(f"expected paths of {what}, got {_shown(value)}", f"give a list of paths of {what}")
        return tuple(path(what)(item, where) for item in value)
    return check


def law_files(value, where: Where) -> tuple:
    """The --law files: paths (one alone, or several) of existing regular files."""
    return tuple(existing_file("law file (a wiring or scenario JSON file)")(item, Where(item, where.entry))
                 for item in paths("law files")(value, where))


_SIGNAL = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*\.\S+$")


def overrides(value, where: Where) -> tuple:
    """--set values: None or a mapping {'comp.var': value}, a value a bool, an integer, a finite
    number or a text; returned as a tuple of (name, value) pairs in the order given."""
    if value is None:
        return ()
    if isinstance(value, tuple) and all(isinstance(p, tuple) and len(p) == 2 for p in value):
        value = dict(value)  # the pairs these checks made (a copy of an options object)
    if not hasattr(value, "items") or not callable(value.items):
        raise where.refuse(f"expected a mapping {{'component.variable': value}}, got {_shown(value)}",
                           "give a dict, e.g. {'vehicle.h0': 91000.0} (on the command line: --set vehicle.h0=91000)")
    pairs = []
    for name, item in value.items():
        if not isinstance(name, str) or not _SIGNAL.match(name):
            raise where.refuse(f"cannot read the name {_shown(name)}: no component.variable",
                               "name a value component.variable (e.g. vehicle.h0)")
        plain = _plain_value(item)
        if plain is None:
            raise where.refuse(f"{name}: the value {_shown(item)} is not a finite number, a Boolean or a text",
                               "give a finite number in SI, true/false or a text")
        pairs.append((name, plain))
    return tuple(pairs)


def _plain_value(item):
    """A --set value as bool, int, float or str (numpy's scalars converted); None for another
    type, a number that is not finite, or an integer beyond the float range."""
    if type(item).__module__ == "numpy" and type(item).__name__ == "bool_":
        return bool(item)
    if isinstance(item, (bool, str)):
        return item
    if _is_integer(item):
        return int(item) if _as_float(item) is not None else None
    if _is_number(item):
        value = _as_float(item)
        return value if value is not None and math.isfinite(value) else None
    return None


def formats(value, where: Where) -> tuple:
    """Time series formats: "csv", "parquet", or several of them; a single text is one format."""
    from aotv_cosim.output.runner import FORMATS

    given = [value] if isinstance(value, str) else value
    if not hasattr(given, "__iter__") or isinstance(given, (bytes, dict)):
        raise where.refuse(f"expected formats, got {_shown(value)}", "give csv and/or parquet")
    given = tuple(given)
    unknown = [f for f in given if f not in FORMATS]
    if unknown or not given or len(set(given)) != len(given):
        shown = ", ".join(map(repr, unknown)) or ("(none given)" if not given else "a format given twice")
        raise where.refuse(f"unknown time series format(s) {shown}", "give csv and/or parquet")
    return given


def scheduler(value, where: Where):
    """A Dask scheduler address (tcp://HOST:PORT, HOST:PORT, ...) or a distributed.Client; None:
    local workers."""
    if value is None or type(value).__module__.split(".")[0] == "distributed":
        return value
    if not isinstance(value, str) or not value.strip() or "\0" in value or any(c.isspace() for c in value):
        raise where.refuse(f"expected a Dask scheduler address, got {_shown(value)}",
                           "give tcp://HOST:PORT (e.g. tcp://127.0.0.1:8786) or a distributed.Client")
    return value


def grids(value, where: Where) -> tuple:
    """Sweep grids: {"comp.var": values} or grid texts "comp.var=LOW:HIGH:N" / "comp.var=A,B,C";
    returned as ((name, (values...)), ...). Each value finite, each name given once, at most
    MAX_POINTS points per grid and together."""
    if isinstance(value, str) or value is None:
        raise where.refuse(f"expected grids, got {_shown(value)}",
                           'give {"comp.var": [values]} or a list of "comp.var=LOW:HIGH:N"')
    items = value.items() if hasattr(value, "items") else None
    if items is None and not hasattr(value, "__iter__"):
        raise where.refuse(f"expected grids, got {_shown(value)}",
                           'give {"comp.var": [values]} or a list of "comp.var=LOW:HIGH:N"')
    result = []
    for item in (items if items is not None else value):
        if isinstance(item, str):
            name, values = parse_grid(item, where)
        else:
            name, values = item
            if not isinstance(name, str) or not _SIGNAL.match(name):
                raise where.refuse(f"cannot read the grid name {_shown(name)}", "name a parameter component.variable")
            if isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
                raise where.refuse(f"{name}: expected a list of values, got {_shown(values)}", "give a list of numbers")
            values = list(values)
            if not values:
                raise where.refuse(f"the grid of {name} has no value", "give at least one value per grid")
            if len(values) > MAX_POINTS:
                raise where.refuse(f"the grid of {name} has {len(values)} values", f"give at most {MAX_POINTS}")
            values = [number(what=f"{name} value")(v, where) for v in values]
        result.append((name, tuple(values)))
    if not result:
        raise where.refuse("no grid given", "give at least one --grid COMP.VAR=LOW:HIGH:N")
    names = [name for name, _ in result]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise where.refuse(f"{', '.join(twice)} is given by several grids",
                           "give each parameter one --grid (list its values as A,B,C)")
    total = math.prod(len(values) for _, values in result)
    if total > MAX_POINTS:
        raise where.refuse(f"the grids make {total} points", f"give at most {MAX_POINTS} points (fewer values per "
                                                             "grid, or several sweeps)")
    return tuple(result)


def parse_grid(text: str, where: "Where | None" = None) -> tuple:
    """(parameter, values) of a grid `comp.var=LOW:HIGH:N` or `comp.var=A,B,C`; refused if
    malformed, with N < 1 or N > MAX_POINTS (before the values are made), or a value not finite."""
    import numpy as np

    where = where or Where(None, "--grid")
    name, _, spec = text.partition("=")
    fix = "write COMP.VAR=LOW:HIGH:N (e.g. vehicle.gamma0=-0.03:-0.01:9) or COMP.VAR=A,B,C"
    name = name.strip()
    if not _SIGNAL.match(name) or not spec:
        raise where.refuse(f"cannot read the grid {text!r}", fix)
    try:
        if ":" in spec:
            low, high, points = spec.split(":")
            if not 1 <= int(points) <= MAX_POINTS:
                raise where.refuse(f"the grid {text!r} asks for {int(points)} points", f"give N from 1 to {MAX_POINTS}")
            values = np.linspace(float(low), float(high), int(points))
        else:
            values = np.array([float(v) for v in spec.split(",")])
    except ValueError:
        raise where.refuse(f"cannot read the grid {text!r}", fix) from None
    if not np.all(np.isfinite(values)):
        raise where.refuse(f"the grid {text!r} has a value that is not finite", fix)
    return name, tuple(float(v) for v in values)


def bracket(value, where: Where) -> tuple:
    """The corridor's (steep, shallow) entry flight-path angles, rad: two finite numbers, both in
    (-pi/2, 0) (an entry descends and cannot pass the vertical), steep < shallow."""
    fix = "give STEEP SHALLOW with -pi/2 < STEEP < SHALLOW < 0 (rad), e.g. --bracket -0.08 -0.002"
    if isinstance(value, (str, bytes, Mapping, AbstractSet)) or not hasattr(value, "__len__") or len(value) != 2 \
            or not all(map(_is_number, value)):
        raise where.refuse(f"expected two numbers (steep, shallow), got {_shown(value)}", fix)
    steep, shallow = map(float, value)
    if not (math.isfinite(steep) and math.isfinite(shallow) and -math.pi / 2 < steep < shallow < 0.0):
        raise where.refuse(f"the bracket ({steep!r}, {shallow!r}) rad is not a finite range from steep to "
                           "shallow within (-pi/2, 0)", fix)
    return steep, shallow


def check_fits(rows: int, columns: int, file, entry="--runs") -> None:
    """Refuse, before any run, `rows` campaign rows of `columns` values whose memory
    (ROW_CELL_BYTES a value) passes half of this machine's physical memory."""
    need = rows * columns * ROW_CELL_BYTES
    try:
        memory = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return
    if need > memory / 2:
        most = int(memory / 2 / (columns * ROW_CELL_BYTES))
        raise InputError(f"{rows} rows of {columns} values would hold about {need / 2**30:.1f} GiB in memory, "
                         f"more than half of this machine's {memory / 2**30:.1f} GiB", file=file, entry=entry,
                         fix=f"give at most {most} runs (or run parts of the campaign with other seeds)")


RESERVED_LAW_NAMES = ("laws", "rows", "failures", "scorecard", "report", "benchmark")
"""Names a law may not have (compared ignoring case): the benchmark folder's own files and folders
(laws/ holds the generated scenarios; rows.*, scorecard.*, report.md, benchmark.png, failures.jsonl)."""


def law_name(name: str, file, entry="--law") -> str:
    """`name` (a law's file name without .json) if it can name a law's campaign folder inside the
    benchmark folder; refused when it would alias the folder's own structure: '.', '..' or any
    name starting with a dot (hidden, and the folder's lock and record), a reserved name, or a
    generated file's name."""
    from aotv_cosim.output.outdir import LOCK, RECORD

    generated = {"rows.csv", "rows.parquet", "scorecard.csv", "scorecard.json", "report.md", "benchmark.png",
                 "failures.jsonl", LOCK, RECORD}
    folded = name.casefold()
    if not name or name.startswith(".") or folded in RESERVED_LAW_NAMES or folded in generated \
            or folded.split(".")[0] in RESERVED_LAW_NAMES:
        raise InputError(f"the law name {name!r} (from the file name) would alias the benchmark folder's own "
                         "files or folders", file=file, entry=entry,
                         fix=f"rename the file: a law name may not start with '.' nor be one of "
                             f"{', '.join(RESERVED_LAW_NAMES)} (any case)")
    return name
