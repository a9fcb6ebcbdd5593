"""An output folder claimed for one run or campaign: usable, and used by nobody else meanwhile.

`claimed(folder, names)` makes the folder if needed and refuses it with an InputError (exit 2)
when it cannot serve: a file (or /dev/null) in its place, not writable (checked by writing the
lock file), one of the result `names` left there as a folder, or another run holding it. The
claim is an exclusive `flock` on `folder/.lock`, held until the `with` ends and released by the
kernel however the process ends; the file stays (removing it would let a third run lock a new
file while the second still holds the old one) and records the holder's pid.
"""

import contextlib
import fcntl
import os
from pathlib import Path

from aotv_cosim.errors import InputError

LOCK = ".lock"

RUN_FILES = ("timeseries.csv", "timeseries.csv.part", "summary.json", "summary.json.part")
"""What a run writes (besides its plots) and so must not find there as folders."""


def _refuse(folder, cause, fix="choose another --out"):
    return InputError(cause, file=folder, entry="--out", fix=fix)


@contextlib.contextmanager
def claimed(folder, names=RUN_FILES):
    """Hold `folder` for the duration of the `with` (see the module docstring)."""
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise _refuse(folder, "not a folder: a file is in the way",
                      "remove the file or choose another --out") from None
    except OSError as exc:
        raise _refuse(folder, f"cannot make the output folder: {exc.strerror}") from None
    if not folder.is_dir():
        raise _refuse(folder, "not a folder: a file is in the way", "remove the file or choose another --out")
    for name in names:
        if (folder / name).is_dir():
            raise _refuse(folder, f"{name} is a folder left in the way of a result file",
                          f"remove {folder / name} or choose another --out")
    lock = folder / LOCK
    try:
        fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o644)
    except OSError as exc:
        raise _refuse(folder, f"the output folder is not writable: {exc.strerror}") from None
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 32, 0).decode(errors="replace").strip() or "unknown"
            raise _refuse(folder, f"the output folder is in use by another run (pid {holder})",
                          "wait for that run to end or choose another --out") from None
        try:
            os.ftruncate(fd, 0)
            os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        except OSError as exc:
            raise _refuse(folder, f"the output folder is not writable: {exc.strerror}") from None
        yield folder
    finally:
        os.close(fd)
