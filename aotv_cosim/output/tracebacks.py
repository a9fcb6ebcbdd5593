"""The user's traceback where they look: an FMU's Python traceback (what `fmu.slave` logs when a
law's `do_step` raises, kept in summary.json `error_detail.traceback`) made short for the console,
with the user's source file named by its full path.

The FMU's copy of a user's source is named in the traceback by the source's file name
(`MyLaw.py`, line numbers the user's); `user_source` finds which file of the user's that is, from
the wiring the run loaded.
"""

import re
from pathlib import Path

FRAME = re.compile(r'^  File "(?P<file>[^"]+)", line (?P<line>\d+), in (?P<function>.+)$')
"""A frame's first line in a Python traceback."""


def user_source(system, component) -> "Path | None":
    """The full path of the .py source the wiring of `system` (a loaded `model.system.System`) names
    for `component`, or None when that component is no user source (an FMU file, a shipped name)."""
    comp = system.components.get(component) if component else None
    if comp is None or not str(comp.fmu_ref).endswith(".py"):
        return None
    return (Path(system.path).parent / comp.fmu_ref).resolve()


def short_traceback(text: str, source=None, frames: int = 3) -> list:
    """The last `frames` frames and the exception of the Python traceback `text`, one line each:
    `FILE, line N, in FUNCTION: CODE` and `EXCEPTION: MESSAGE`. A frame whose file has the name of
    `source` (the user's .py file) is shown with that full path."""
    lines = text.strip().splitlines()
    found = []
    for k, line in enumerate(lines):
        match = FRAME.match(line)
        if match:
            code = lines[k + 1].strip() if k + 1 < len(lines) and lines[k + 1].startswith("    ") else ""
            file = match["file"]
            if source is not None and Path(file).name == Path(source).name:
                file = str(source)
            found.append(f"{file}, line {match['line']}, in {match['function']}" + (f": {code}" if code else ""))
    exception = next((line.strip() for line in reversed(lines) if line.strip() and not line.startswith(" ")), "")
    return found[-frames:] + ([exception] if exception else [])


def first_user_line(text: str, source=None) -> str:
    """One line for the console: the innermost frame in the user's file `source` (else the innermost
    frame) and the exception: `FILE, line N, in FUNCTION: CODE -> EXCEPTION: MESSAGE`."""
    short = short_traceback(text, source, frames=100)
    if not short:
        return ""
    frames, exception = short[:-1], short[-1]
    own = [f for f in frames if source is not None and f.startswith(str(source))]
    where = (own or frames or [""])[-1]
    return f"{where} -> {exception}" if where else exception
