"""An output folder claimed for one run or campaign: usable, used by nobody else meanwhile, and
holding a record of what this package wrote there, so nothing else in it is ever overwritten or
deleted.

`claimed(folder, names)` makes the folder if needed and refuses it with an InputError (exit 2)
when it cannot serve: a file (or /dev/null) in its place, not writable (checked by writing the
lock file), one of the result `names` left there as a folder, one of them there as a file this
package did not write (a user's file of that name), or another run holding it. The claim is an
exclusive `flock` on `folder/.lock`, held until the `with` ends and released by the kernel however
the process ends; the file stays (removing it would let a third run lock a new file while the
second still holds the old one) and records the holder's pid.

The record is `folder/.aotv-written`: the names (relative to the folder, one per line) of the
files and folders the package wrote there. When a claim ends, however it ends, every file of the
folder that appeared or changed while it was held is added (a new subfolder with all it holds);
`remove_written` deletes only recorded files. A folder written by a version of the package before
the record (it has a `.lock` and no record) is taken as written by the package for the result
names it holds. A claim under which nothing was written (the command refused or interrupted before
its first file) leaves nothing: the lock and record it made are removed, and the folder too if it
made it.
"""

import contextlib
import fcntl
import fnmatch
import os
from pathlib import Path

from aotv_cosim.errors import InputError

LOCK = ".lock"
RECORD = ".aotv-written"

RUN_FILES = ("timeseries.csv", "timeseries.csv.part", "summary.json", "summary.json.part")
"""What a run writes (besides its plots) and so must not find there as folders."""
RUN_OUTPUTS = (*RUN_FILES, "timeseries.parquet", "timeseries.parquet.part", "overview*.png", "plot_*.png")
"""Every name a run may write (patterns): found there unrecorded, they are a user's files."""


def _refuse(folder, cause, fix="choose another --out"):
    return InputError(cause, file=folder, entry="--out", fix=fix)


def written(folder) -> set:
    """The names the record of `folder` holds (empty without a record)."""
    try:
        text = (Path(folder) / RECORD).read_text(encoding="utf-8")
    except (OSError, ValueError):
        return set()
    return {line for line in text.splitlines() if line}


def _record(folder: Path, names, always=False) -> None:
    """Add `names` to the record of `folder` (written whole via a rename; with `always`, written
    even when it has them all)."""
    known = written(folder)
    if set(names) <= known and not (always and not (folder / RECORD).is_file()):
        return
    part = folder / (RECORD + ".part")
    try:
        part.write_text("".join(f"{name}\n" for name in sorted(known | set(names))), encoding="utf-8")
        os.replace(part, folder / RECORD)
    except BaseException:  # a full disk: the record stays as it was, no .part beside it
        with contextlib.suppress(OSError):
            part.unlink(missing_ok=True)
        raise


def _listing(folder: Path) -> dict:
    """{name: (inode, mtime_ns, size, is_dir)} of the entries of `folder` (not descending)."""
    found = {}
    with os.scandir(folder) as entries:
        for entry in entries:
            try:
                info = entry.stat(follow_symlinks=False)
            except OSError:
                continue
            found[entry.name] = (info.st_ino, info.st_mtime_ns, info.st_size, entry.is_dir(follow_symlinks=False))
    return found


def _tree(folder: Path, prefix: str) -> list:
    """`prefix` and the relative names of everything under the folder `folder`."""
    names = [prefix]
    for root, dirs, files in os.walk(folder):
        rel = Path(root).relative_to(folder)
        names += [str(Path(prefix) / rel / name) for name in dirs + files]
    return names


def _changed(folder: Path, before: dict) -> list:
    """Names of the folder's entries that appeared or changed since `before` (`_listing`): a new
    folder with its whole content; an existing folder is claimed on its own if the package writes
    into it."""
    names = []
    for name, now in _listing(folder).items():
        if name in (LOCK, RECORD, RECORD + ".part"):
            continue
        if now[3]:
            if name not in before:
                names += _tree(folder / name, name)
        elif before.get(name) != now:
            names.append(name)
    return names


def _legacy(folder: Path, listing) -> bool:
    """True for a folder written by a version of the package before the record: no record, and a
    lock file in it or in one of its subfolders (a benchmark's law campaigns)."""
    if RECORD in listing:
        return False
    return LOCK in listing or any(info[3] and (folder / name / LOCK).is_file() for name, info in listing.items())


def _check_names(folder: Path, names, listing, adopt=False) -> None:
    """Refuse a result name left there as a folder, or there as a file the package did not write
    (unless told to `adopt` them)."""
    ours = written(folder)
    legacy = adopt or _legacy(folder, listing)
    for pattern in names:
        for name in fnmatch.filter(listing, pattern) if any(c in pattern for c in "*?[") else \
                [pattern] if pattern in listing else []:
            if listing[name][3]:
                raise _refuse(folder, f"{name} is a folder left in the way of a result file",
                              f"remove {folder / name} or choose another --out")
            if name not in ours and not legacy and not name.endswith(".part"):
                raise _refuse(folder, f"{name} is there and was not written by aotv-cosim (it is not in "
                                      f"{RECORD}): it would be overwritten",
                              f"move {folder / name} away or choose another --out")


@contextlib.contextmanager
def claimed(folder, names=RUN_OUTPUTS, adopt=False):
    """Hold `folder` for the duration of the `with` (see the module docstring); `names`: the
    files (or fnmatch patterns) the command may write there. `adopt`: take those found there as
    the package's (a campaign resumed on the user's word: its rows are checked to be of the same
    campaign before any is rewritten)."""
    folder = Path(folder)
    created = not os.path.lexists(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except FileExistsError:
        raise _refuse(folder, "not a folder: a file is in the way",
                      "remove the file or choose another --out") from None
    except OSError as exc:
        raise _refuse(folder, f"cannot make the output folder: {exc.strerror}") from None
    if not folder.is_dir():
        raise _refuse(folder, "not a folder: a file is in the way", "remove the file or choose another --out")
    try:
        before = _listing(folder)
    except OSError as exc:
        raise _refuse(folder, f"cannot list the output folder: {exc.strerror}") from None
    _check_names(folder, names, before, adopt)  # before the lock: a refused claim leaves nothing
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
            # the record exists from the claim on, so a folder with a lock and no record is an
            # earlier version's; resumed, or written by that version, its result files are ours
            adopted = [name for name in before for pattern in names if fnmatch.fnmatch(name, pattern)] \
                if adopt or _legacy(folder, before) else []
            _record(folder, adopted, always=True)
        except OSError as exc:
            raise _refuse(folder, f"the output folder is not writable: {exc.strerror}") from None
        try:
            yield folder
        finally:
            with contextlib.suppress(OSError):
                _record(folder, _changed(folder, before))
            _unused_removed(folder, created, [name for name in (RECORD, LOCK) if name not in before])
    finally:
        os.close(fd)


def _unused_removed(folder: Path, created: bool, made: list) -> None:
    """When the command wrote nothing in `folder` (refused or interrupted before its first file):
    remove the record and lock this claim `made` there, and the folder if the claim `created` it
    and nothing else is in it; the lock is still held (a claim made meanwhile has a lock file of
    its own there, and the folder then stays)."""
    with contextlib.suppress(OSError):
        if written(folder):
            return
        for name in made:
            (folder / name).unlink(missing_ok=True)
        if created and not os.listdir(folder):
            folder.rmdir()


def remove_written(folder) -> list:
    """Delete what the package recorded writing in `folder` (files, then the folders left empty),
    and the folder itself when nothing else is left in it; returns the names kept (not written by
    the package)."""
    folder = Path(folder)
    ours = written(folder)
    for name in sorted(ours, key=lambda n: -n.count(os.sep)):
        path = folder / name
        with contextlib.suppress(OSError):
            if path.is_dir() and not path.is_symlink():
                path.rmdir()  # only once empty: a user's file inside keeps it
            else:
                path.unlink()
    if not folder.is_dir():
        return []
    left = {name for name in ours if os.path.lexists(folder / name)}
    (folder / RECORD).write_text("".join(f"{name}\n" for name in sorted(left)), encoding="utf-8")
    kept = sorted(name for name in os.listdir(folder) if name not in (LOCK, RECORD))
    if not kept:
        for name in (RECORD, LOCK):
            with contextlib.suppress(OSError):
                (folder / name).unlink()
        with contextlib.suppress(OSError):
            folder.rmdir()
    return kept
