"""C kernels of the predictors: compiled on first use into the FMU cache, loaded with ctypes.

A kernel is one C source string that repeats a Python loop of `guidance` with the same
operations in the same order (`npc_kernel`, `npc_bank_kernel`). `FLAGS` tell the compiler to
keep IEEE arithmetic as written: no fused multiply-add contraction, no builtin replacement of the
C library's exp, pow, sin and cos (the functions Python's `math` and float `**` call), no fast
math; so the compiled loop gives the Python loop's numbers to the bit.

The shared library is looked for beside the kernel's module (an FMU that bundles it), then in the
`kernels` folder of the FMU cache (`kernel_dir`), where it is compiled on first use when a C
compiler is found; this works from any copy of the package, also the runtime an FMU bundles.
Without a compiler (or when the compilation fails) `load` returns None and the caller runs its
Python loop.
"""

import ctypes
import hashlib
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

FLAGS = ("-O2", "-shared", "-fPIC", "-ffp-contract=off", "-fno-builtin", "-fno-fast-math")
"""Compiler options: optimised, IEEE arithmetic as written (no fused multiply-add, no builtin
replacement of exp, pow, sin, cos)."""


def library_name(stem: str, source: str) -> str:
    """File name of the compiled `source`: lib<stem>_<16 hex digits of its hash with FLAGS>.so
    (it changes with the source and the options)."""
    return f"lib{stem}_{hashlib.sha256((source + ' '.join(FLAGS)).encode()).hexdigest()[:16]}.so"


def compiler():
    """The C compiler command (gcc, else cc), or None."""
    return shutil.which("gcc") or shutil.which("cc")


def compile_library(source: str, library: str, directory) -> Path:
    """Compile `source` into `directory`/`library` (written atomically: concurrent workers may
    compile at once) and return its path. Raises OSError or CalledProcessError on failure."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=directory) as tmp:
        source_file = Path(tmp) / "kernel.c"
        source_file.write_text(source)
        subprocess.run([compiler() or "cc", *FLAGS, "-o", library, source_file.name, "-lm"], check=True,
                       capture_output=True, cwd=tmp)  # relative names: no temporary path in the binary
        os.replace(Path(tmp) / library, directory / library)
    return directory / library


def kernel_dir() -> Path:
    """Folder of compiled kernels: `kernels` in the FMU cache folder, chosen by the rule of
    `fmu.build.cache_dir` ($AOTV_COSIM_CACHE, else $XDG_CACHE_HOME/aotv-cosim, else
    ~/.cache/aotv-cosim), written out here because an FMU's bundled runtime has no fmu.build."""
    given = os.environ.get("AOTV_COSIM_CACHE")
    root = Path(given) if given else Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "aotv-cosim"
    return root / "kernels"


def _cached_library(source: str, library: str):
    """The kernel in `kernel_dir`, compiled there if missing; None without a compiler or when
    the compilation fails."""
    path = kernel_dir() / library
    if path.is_file():
        return path
    if compiler() is None:
        return None
    try:
        return compile_library(source, library, path.parent)
    except (OSError, subprocess.CalledProcessError):
        return None


def load(source: str, library: str, beside: Path):
    """The ctypes.CDLL of `library` (compiled from `source`): the copy beside the module file
    `beside`, else the FMU cache's (compiled there on first use); None if neither loads."""
    for path in (Path(beside).with_name(library), _cached_library(source, library)):
        if path is not None and path.is_file():
            try:
                return ctypes.CDLL(str(path))
            except OSError:
                continue
    return None
