"""An FMU's extracted folder (`extracted`), shared by the runs of a process and keyed by the FMU
file's content, and the sys.path entries that loading an FMU's Python code adds (`demote_new_paths`)."""

import hashlib
import sys
from pathlib import Path

from aotv_cosim.fmu import build as fmu_build
from aotv_cosim.model.archives import extract_to

_DIGESTS: dict = {}
"""(path, size, mtime) -> content digest of the FMU files seen by this process."""


def extracted(fmu_path: Path) -> Path:
    """Folder holding the extracted FMU, shared between runs and keyed by the file's content."""
    stat = Path(fmu_path).stat()
    key = (str(fmu_path), stat.st_size, stat.st_mtime_ns)
    if key not in _DIGESTS:
        _DIGESTS[key] = hashlib.sha256(Path(fmu_path).read_bytes()).hexdigest()[:20]
    digest = _DIGESTS[key]
    target = fmu_build.cache_dir() / "extracted" / digest
    if not target.is_dir():
        extract_to(fmu_path, target)  # its members were checked when the wiring was loaded
    return target


def demote_new_paths(before: list) -> None:
    """Move the sys.path entries inserted since `before` (a copy) to its end.

    A pythonfmu FMU inserts its resources folder first on the host's sys.path at every
    instantiation. This package's FMUs bundle their runtime under names of their own, but another
    tool's pythonfmu FMU may bundle modules under common names (its own `pythonfmu`, a helper
    module), which would then shadow the installed ones in every process started later from this
    one (a Monte Carlo or Dask worker spawned with this sys.path). At the end the folder still
    serves the FMU's own later imports.
    """
    n_new = len(sys.path) - len(before)
    if n_new > 0 and sys.path[n_new:] == before:
        sys.path[:] = before + [p for p in sys.path[:n_new] if p not in before]
