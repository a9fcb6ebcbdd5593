"""Limits on FMU and SSP archives, checked from the zip directory before anything is extracted,
and an extraction that leaves nothing behind when it fails.

A zip archive states each member's uncompressed size in its directory, and Python's zipfile
never writes more than that size (a member that inflates further fails its CRC check). So the
sizes are checked before extraction: a few megabytes of compressed zeros cannot fill the cache.
"""

import os
import shutil
import tempfile
import zipfile
import zlib
from pathlib import Path

from aotv_cosim.errors import InputError

MAX_MEMBERS = 10_000
"""Most members an archive may have (this package's FMUs have about 60)."""
MAX_TOTAL_BYTES = 512 * 2**20
"""Largest total uncompressed size, bytes (this package's FMUs are about 1.2 MB)."""
MAX_RATIO = 200.0
"""Largest compression ratio of a member over `RATIO_FLOOR_BYTES`: code and data compress about
3-10x; a ratio of hundreds is padding made to inflate (zeros compress about 1000x)."""
RATIO_FLOOR_BYTES = 2**20
DESCRIPTORS = ("modelDescription.xml", "SystemStructure.ssd")
"""Members read (and so decompressed) before anything else: a damaged one is reported as such."""
DAMAGED = (zipfile.BadZipFile, zlib.error, OSError, EOFError, NotImplementedError, RuntimeError)
"""What zipfile raises for a member it cannot read back: a CRC mismatch, a corrupt deflate stream
(zlib.error), a truncated archive, an unknown compression method, an encrypted member."""


def check_sizes(archive: zipfile.ZipFile, path, *, file=None, entry=None) -> None:
    """Refuse an archive with too many members, a repeated member name, a member that inflates
    more than `MAX_RATIO`, or more than `MAX_TOTAL_BYTES` in all, or whose descriptor
    (`DESCRIPTORS`) cannot be read back (InputError naming `file` and `entry` when given, else the
    archive)."""
    name = Path(path).name
    infos = archive.infolist()

    def refuse(cause, fix):
        raise InputError(f"{name}: {cause}" if file else cause, file=file or path, entry=entry, fix=fix)

    if len(infos) > MAX_MEMBERS:
        refuse(f"{len(infos)} members, more than {MAX_MEMBERS}", "give an archive with fewer files")
    seen, total = set(), 0
    for info in infos:
        if info.filename in seen:
            refuse(f"member {info.filename!r} appears twice", "rebuild the archive with each file once")
        seen.add(info.filename)
        if info.file_size > RATIO_FLOOR_BYTES and info.file_size > MAX_RATIO * max(info.compress_size, 1):
            refuse(f"member {info.filename!r} inflates {info.compress_size} to {info.file_size} bytes "
                   f"(more than {MAX_RATIO:g}x)", "give an archive without padding made to inflate")
        total += info.file_size
    if total > MAX_TOTAL_BYTES:
        refuse(f"{total} bytes uncompressed, more than {MAX_TOTAL_BYTES}",
               "give a smaller archive (members are checked before extraction)")
    for member in seen.intersection(DESCRIPTORS):
        try:
            archive.read(member)
        except DAMAGED as exc:
            refuse(damaged(member, exc), "give an intact archive (rebuild or copy it again)")


def damaged(member: str, exc: Exception) -> str:
    """'member M is corrupt (WHY)' for an error zipfile raised reading it (one of DAMAGED)."""
    return f"member {member} is corrupt ({_why(exc)})"


def _why(exc: Exception) -> str:
    """The damage an error of DAMAGED describes ('invalid deflate data: ...' for zlib's)."""
    return f"invalid deflate data: {str(exc).split(': ', 1)[-1]}" if isinstance(exc, zlib.error) else str(exc)


def extract_to(path, folder: Path, *, file=None, entry=None) -> Path:
    """Extract the checked archive `path` into `folder` (made atomically, kept if another process
    made it first); a failed extraction (a corrupt member, a full disk) removes what it wrote
    and raises InputError."""
    folder = Path(folder)
    folder.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{folder.name}.", dir=folder.parent))
    try:
        with zipfile.ZipFile(path) as archive:
            archive.extractall(staging)
    except DAMAGED as exc:
        shutil.rmtree(staging, ignore_errors=True)
        raise InputError(f"cannot extract {Path(path).name}: {_why(exc)}", file=file or path, entry=entry,
                         fix="give an intact archive (rebuild or copy it again)") from None
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    try:
        os.replace(staging, folder)
    except OSError:  # another process extracted the same archive meanwhile
        shutil.rmtree(staging, ignore_errors=True)
    return folder


_INTACT: set = set()
"""(path, size, mtime) of the archives whose members this process found intact."""


def check_fmu_members(path, model_identifier: str, *, fmi_version="2.0", file=None, entry=None) -> None:
    """Refuse an FMU without the co-simulation binary this platform loads
    (binaries/<platform>/<modelIdentifier><extension>, the platform named as FMI `fmi_version`
    names it, so also one whose modelIdentifier names no binary), or with a member whose data
    fails its CRC check (read, not extracted)."""
    from fmpy import platform, platform_tuple, sharedLibraryExtension

    path = Path(path)
    platform = platform if fmi_version == "2.0" else platform_tuple
    binary = f"binaries/{platform}/{model_identifier}{sharedLibraryExtension}"
    with zipfile.ZipFile(path) as archive:
        names = archive.namelist()
        if binary not in names:
            present = sorted(n for n in names if n.startswith("binaries/") and not n.endswith("/"))
            raise InputError(f"{path.name} has no {binary} (modelIdentifier {model_identifier!r}, "
                             f"binaries present: {', '.join(present) or 'none'})", file=file or path,
                             entry=entry, fix=f"give an FMU built for {platform} whose binary is named "
                                              "after its modelIdentifier")
        stat = path.stat()
        key = (str(path), stat.st_size, stat.st_mtime_ns)
        if key in _INTACT:
            return
        bad = _first_damaged(archive)
    if bad is not None:
        raise InputError(f"{path.name}: {bad}" if file else bad,
                         file=file or path, entry=entry,
                         fix="give an intact FMU (rebuild or copy it again)")
    _INTACT.add(key)


def _first_damaged(archive: zipfile.ZipFile):
    """'member M is corrupt (...)' for the first member that cannot be read back (its CRC, its
    deflate stream), else None. Like ZipFile.testzip, but the member of a zlib error is named."""
    for info in archive.infolist():
        try:
            with archive.open(info) as member:
                while member.read(2**20):
                    pass
        except DAMAGED as exc:
            return damaged(info.filename, exc)
    return None
