"""Paths given by the user, checked before they are opened: one InputError line for a path that
cannot be used (symlink loop, NUL byte, over-long name, no permission, a FIFO or device instead
of a file, a file where a folder is needed, a read-only place), never a hang or a traceback.
"""

import errno
import os
import stat
import tempfile
from pathlib import Path

from aotv_cosim.errors import InputError

MAX_DOCUMENT_BYTES = 64 * 2**20
"""Largest scenario, wiring or comparison file read, bytes (the shipped ones are a few kB)."""


def _os_cause(exc) -> str:
    """A short cause for an OSError or ValueError raised on a path."""
    if isinstance(exc, ValueError):
        return "the path holds a NUL byte"
    if isinstance(exc, RuntimeError):
        return "symlink loop"
    return {errno.ELOOP: "symlink loop", errno.ENAMETOOLONG: "a name in the path is too long",
            errno.EACCES: "permission denied", errno.EPERM: "permission denied",
            errno.ENOTDIR: "a part of the path is a file, not a folder",
            errno.ENOENT: "not found", errno.EROFS: "read-only file system"}.get(
        exc.errno, exc.strerror or str(exc))


def resolved(path, *, file=None, entry=None, what="file") -> Path:
    """`path` made absolute with symlinks resolved; InputError for a loop or an unusable name."""
    try:
        return Path(path).resolve()
    except (OSError, RuntimeError, ValueError) as exc:
        raise InputError(f"cannot resolve the path: {_os_cause(exc)}", file=file or path, entry=entry,
                         fix=f"give the path of a {what} (no symlink loop, no NUL byte, names under 255 bytes)"
                         ) from exc


def regular_file(path, *, what="file", file=None, entry=None, max_bytes=None) -> os.stat_result:
    """The stat of `path` if it is a regular file (at most `max_bytes`), else InputError naming
    `file` (default: the path) and `entry`. A FIFO or a device is refused before it is opened:
    reading one would block or never end."""
    where = file or path
    try:
        info = os.stat(path)
    except (OSError, ValueError) as exc:
        cause = "file not found" if isinstance(exc, FileNotFoundError) else f"cannot be read: {_os_cause(exc)}"
        raise InputError(cause if file is None else f"{cause}: {path}", file=where, entry=entry,
                         fix=f"give the path of an existing {what}") from exc
    if stat.S_ISDIR(info.st_mode):
        raise InputError("is a folder" if file is None else f"is a folder: {path}", file=where, entry=entry,
                         fix=f"give the path of a {what}")
    if not stat.S_ISREG(info.st_mode):
        raise InputError("is not a regular file (a FIFO, socket or device)" if file is None else
                         f"not a regular file: {path}", file=where, entry=entry,
                         fix=f"give the path of a {what} on disk")
    if max_bytes is not None and info.st_size > max_bytes:
        raise InputError(f"{info.st_size} bytes, more than {max_bytes}", file=where, entry=entry,
                         fix=f"give a {what} of at most {max_bytes // 2**20} MiB")
    return info


def writable_folder(path, option="--out") -> Path:
    """Make the output folder `path` (and its parents) and check a file can be written in it."""
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
        handle, probe = tempfile.mkstemp(prefix=".write-check-", dir=path)
        os.close(handle)
        os.unlink(probe)
    except (OSError, ValueError) as exc:
        cause = "a file is in the way" if isinstance(exc, (FileExistsError, NotADirectoryError)) \
            else _os_cause(exc)
        raise InputError(f"cannot write an output folder here: {cause}", file=path, entry=option,
                         fix="give a writable folder (not a file, not under a file)") from exc
    return path


def writable_file(path, option="-o") -> Path:
    """Check the output file `path` can be written: a regular file or nothing there yet, in a
    writable folder (which is made). A device such as /dev/null is refused: the writer would
    replace it."""
    path = Path(path)
    try:
        info = os.stat(path)
    except FileNotFoundError:
        info = None
    except (OSError, ValueError) as exc:
        raise InputError(f"cannot write here: {_os_cause(exc)}", file=path, entry=option,
                         fix="give the path of a new or regular file in a writable folder") from exc
    if info is not None and not stat.S_ISREG(info.st_mode):
        kind = "a folder" if stat.S_ISDIR(info.st_mode) else "not a regular file"
        raise InputError(f"cannot write here: {kind}", file=path, entry=option,
                         fix="give the path of a new or regular file")
    writable_folder(path.parent if str(path.parent) else Path("."), option)
    return path
