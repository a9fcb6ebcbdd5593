"""Build the FMUs of ``fmus_src``, or a user's FMU source file from any folder, with pythonfmu:
content-hash cache, compliant, reproducible.

An FMU is named by its source (`fmu_source`): a name of fmus_src, or a path ending in .py (a
user's law, see docs/writing-a-guidance-law.md; `check_source` imports it apart and returns its
class, reporting the file and line of a failure; canGetAndSetFMUstate is declared true only for
an AotvSlave, whose state snapshot the runtime provides).

Every FMU bundles the runtime part of this package (`RUNTIME`: the physics, the guidance laws and
the adapter base classes) so it runs where aotv-cosim is not installed, under a name of its own
(`isolate`): the runtime as ``aotv_cosim_<hash16>``, pythonfmu inside it, the FMU's module as
``<Name>_<hash16>`` (its source hash), imports rewritten. Python hosts keep one module per name
for the whole process, so with one shared name the first FMU's copy (from a folder a host may
have deleted since, from other sources) would serve every later one; named apart, any number of
FMUs of any versions, in any number of systems, share a process. The build then rewrites
the archive so that the same sources give the same bytes: the modelDescription gets a GUID
derived from the sources and the generated XML (also written to `TOKEN_FILE`, which the lean
wrapper checks at instantiation), no generation date, and zip entries are written in sorted
order with a fixed timestamp. On Linux the binary is patched to load in plain C FMI hosts
(`fmu_native`). Finally `fmpy validate` must report no problem. With ``fmi_version=3`` the FMU is
built as FMI 3.0 instead (`aotv_cosim.fmu.build_fmi3`, also for a pythonfmu3 class).
"""

import ast
import difflib
import hashlib
import io
import os
import re
import shutil
import sys
import tempfile
import uuid
import zipfile
from pathlib import Path
from xml.etree import ElementTree

import pythonfmu
from pythonfmu.builder import FmuBuilder

from aotv_cosim.errors import AotvError, BuildError, InputError
from aotv_cosim.paths import regular_file
from aotv_cosim.fmu import native as fmu_native

PACKAGE_DIR = Path(__file__).resolve().parents[1]
RUNTIME = ("__init__.py", "laws.py", "fmu/__init__.py", "fmu/slave.py", "fmu/actuator_slave.py", "fmu/guidance_slave.py",
           "fmu/vehicle_slave.py", "physics", "guidance")
"""Paths inside aotv_cosim that every FMU bundles (they import numpy, scipy and pythonfmu only)."""
RUNTIME_PATTERNS = ("*.py", "*.csv")
"""Files bundled from the RUNTIME folders: modules and the data tables they read beside them."""
BUILD_INFO = "resources/aotv_cosim_build.txt"
"""Archive member holding the source hash an FMU was built from."""
TOKEN_FILE = "resources/aotv_cosim_guid.txt"
"""Archive member holding the GUID (FMI 2.0) or instantiationToken (FMI 3.0) the FMU was built with,
one line: the lean wrapper refuses to instantiate with another (aotv_cosim/fmu/fmi_core.c)."""
ZIP_DATE = (1980, 1, 1, 0, 0, 0)
BUILD_HOOKS = []
"""Callables hook(name, stage) told of every build `ensure_fmu` makes: stage "start" before it,
"done" after (the command line's progress, aotv_cosim.fmu.build_progress)."""
BUILD_FORMAT = ("6: explicit variability, Linux binary loads in C hosts, FMU state get/set, runtime "
                "under a name of its own, GUID in resources")
"""Version of the rewrite below; part of the source hash, so a change rebuilds cached FMUs."""


def fmus_src_dir() -> Path:
    """The fmus_src folder: inside the installed package (wheel) or beside it (source checkout)."""
    for candidate in (PACKAGE_DIR / "fmus_src", PACKAGE_DIR.parent / "fmus_src"):
        if candidate.is_dir():
            return candidate
    raise BuildError("fmus_src not found", file=str(PACKAGE_DIR.parent / "fmus_src"),
                     fix="reinstall aotv-cosim or run from a source checkout")


def cache_dir() -> Path:
    """FMU cache folder: $AOTV_COSIM_CACHE, else $XDG_CACHE_HOME/aotv-cosim, else ~/.cache/aotv-cosim."""
    root = os.environ.get("AOTV_COSIM_CACHE")
    if root:
        return Path(root)
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg) if xdg else Path.home() / ".cache") / "aotv-cosim"


def available_fmus() -> list:
    """Names of the FMUs defined in fmus_src (one class per module)."""
    return sorted(p.stem for p in fmus_src_dir().glob("*.py") if not p.stem.startswith("_"))


def is_source_path(ref) -> bool:
    """True if the FMU reference `ref` names a user's FMU source file (it ends in .py)."""
    return str(ref).endswith(".py")


def fmu_source(ref) -> Path:
    """The source file of an FMU: fmus_src/<ref>.py for a name of this package, else `ref` itself
    when it is a path to a .py file (a user's FMU source, anywhere). InputError when neither."""
    if is_source_path(ref):
        path = Path(ref).resolve()
        try:
            regular_file(path, what="FMU source (.py)")
        except InputError as exc:
            raise InputError(exc.cause, file=str(ref), fix="give the path of a Python file defining one FMU "
                             "class (see docs/writing-a-guidance-law.md)") from None
        return path
    if ref not in available_fmus():
        raise BuildError(f"no FMU named {ref!r} in fmus_src",
                         fix=f"use one of {', '.join(available_fmus())}, a .py FMU source or a .fmu file")
    return fmus_src_dir() / f"{ref}.py"


def check_source(source: Path) -> type:
    """Import a user's FMU source apart from sys.modules and return its FMU class (the concrete
    Fmi2Slave subclass defined in it, as pythonfmu picks it: the longest class hierarchy).

    Importing runs the class checks of `AotvSlave.__init_subclass__` (do_step defined, units
    parsed when instantiated later). InputError naming the file and line of a failure."""
    import importlib.util
    import inspect
    import traceback

    from pythonfmu import Fmi2Slave

    name = f"_aotv_fmu_source_{source.stem}"
    spec = importlib.util.spec_from_file_location(name, source)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses and pickling look the module up while it runs
    try:
        spec.loader.exec_module(module)
    except Exception as exc:
        frames = [f for f in traceback.extract_tb(exc.__traceback__) if Path(f.filename) == source]
        where = f"line {frames[-1].lineno}" if frames else None
        if isinstance(exc, SyntaxError):  # raised while compiling: the line is on the error, not in a frame
            where = f"line {exc.lineno}" if exc.lineno else "(whole file)"
        raise InputError(f"importing it raised {type(exc).__name__}: {exc}", file=str(source), entry=where,
                         fix="fix the source (run `python " + source.name + "` to see the traceback)") from exc
    finally:
        sys.modules.pop(name, None)
    classes = [c for c in vars(module).values() if inspect.isclass(c) and issubclass(c, Fmi2Slave)
               and c.__module__ == name and not inspect.isabstract(c)]
    if not classes:
        raise InputError("defines no concrete FMU class", file=str(source), entry="(top level)",
                         fix="define a subclass of aotv_cosim.laws.AotvSlave (or one of its guidance bases) "
                             "with do_step and every abstract method")
    longest = max(len(c.__mro__) for c in classes)
    chosen = [c for c in classes if len(c.__mro__) == longest]
    if len(chosen) > 1:
        raise InputError(f"defines several FMU classes ({', '.join(c.__name__ for c in chosen)})",
                         file=str(source), entry="(top level)", fix="keep one FMU class per file")
    return chosen[0]


def saves_state(source: Path) -> bool:
    """True if the FMU class of `source` can get and set its FMU state (an AotvSlave: see
    `aotv_cosim.fmu.slave.SAVED_STATE`); written as canGetAndSetFMUstate."""
    from aotv_cosim.fmu.slave import AotvSlave

    return issubclass(check_source(source), AotvSlave)


def _runtime_files():
    for entry in RUNTIME:
        path = PACKAGE_DIR / entry
        if path.is_dir():
            yield from sorted(p for pattern in RUNTIME_PATTERNS for p in path.rglob(pattern)
                              if "__pycache__" not in p.parts)
        else:
            yield path


def source_hash(ref) -> str:
    """SHA-256 over the FMU's module (`fmu_source(ref)`, by file name and content: a user's source
    hashes the same in any folder), the bundled runtime, the pythonfmu version and what the
    Linux binary's patch depends on (`fmu_native.fingerprint`: the building Python's libpython)."""
    digest = hashlib.sha256(f"pythonfmu {pythonfmu.__version__}\nformat {BUILD_FORMAT}\n"
                            f"{fmu_native.fingerprint()}\n".encode())
    source = fmu_source(ref)
    for rel, path in [(f"fmus_src/{source.name}", source),
                      *((p.relative_to(PACKAGE_DIR.parent).as_posix(), p) for p in _runtime_files())]:
        digest.update(f"{rel}\n".encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def built_hash(fmu: Path):
    """The source hash recorded in an FMU built here, or None."""
    try:
        with zipfile.ZipFile(fmu) as archive:
            return archive.read(BUILD_INFO).decode().strip()
    except (OSError, KeyError, zipfile.BadZipFile):
        return None


def built_fmu(ref, fmi_version=None) -> Path:
    """The FMU resolver that builds (`model.fmu_file.FmuResolver`): the up-to-date .fmu of a
    name of fmus_src or of a user's FMU source `ref` (a path ending in .py), built into the cache
    when missing or stale (`ensure_fmu`; `functools.partial(built_fmu, fmi_version=3)` resolves to
    FMI 3.0 FMUs). InputError for a name fmus_src has not, naming close ones."""
    if not is_source_path(ref):
        names = available_fmus()
        if ref not in names:
            close = difflib.get_close_matches(ref, names, n=3)
            hint = f"did you mean {' or '.join(close)}? " if close else ""
            raise InputError(f"no FMU named {ref!r} in this package",
                             fix=f"{hint}give a path to a .fmu file or a .py FMU source (relative to the "
                                 f"wiring file) or one of {', '.join(names)}")
    return ensure_fmu(ref, fmi_version=fmi_version)


def ensure_fmu(ref, out_dir=None, fmi_version=None) -> Path:
    """Path of an up-to-date FMU for fmus_src/<ref>.py, or for the user's source file `ref` (a
    path ending in .py), building it if missing or stale.

    Without out_dir the FMU lives in the cache as <name>-<hash16>.fmu; with it, as <name>.fmu
    (name: the source's file name without .py). fmi_version: 2 or 3 (`aotv_cosim.fmu.build_fmi3`);
    None builds FMI 2.0, or 3.0 for a pythonfmu3 class.
    """
    if _fmi3(ref, fmi_version):
        return _build_fmi3().ensure_fmu(ref, out_dir)
    target, digest = _target(ref, out_dir)
    source = fmu_source(ref)
    name = source.stem
    if target.is_file() and built_hash(target) == digest:
        return target
    if is_source_path(ref):
        check_source(source)  # a broken user source is one error line, before any progress is shown
    for hook in BUILD_HOOKS:
        hook(name, "start")
    target.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="aotv_build_") as tmp:
        raw = _pythonfmu_build(source, Path(tmp))
        _forget_module(source)
        staged = Path(tmp) / "final.fmu"
        _rewrite_reproducibly(raw, staged, digest)
        _validate(staged, source)
        os.replace(staged, target) if staged.stat().st_dev == target.parent.stat().st_dev \
            else shutil.move(staged, target)
    for hook in BUILD_HOOKS:
        hook(name, "done")
    return target


def _forget_module(source: Path) -> None:
    """Drop the module pythonfmu imported from `source` to build it (sys.modules[<stem>]): an FMU
    instantiated later in this process imports its own bundled copy, not a stale one from an
    earlier build of an edited source."""
    module = sys.modules.get(source.stem)
    if module is not None and Path(getattr(module, "__file__", "") or "").resolve() == source.resolve():
        del sys.modules[source.stem]


def _target(ref, out_dir=None):
    """(path of the built FMU, source hash) for the FMU `ref` (a name or a .py source)."""
    name = fmu_source(ref).stem
    digest = source_hash(ref)
    return (Path(out_dir) / f"{name}.fmu" if out_dir else cache_dir() / f"{name}-{digest[:16]}.fmu"), digest


def needs_build(ref, out_dir=None, fmi_version=None) -> bool:
    """True if `ensure_fmu(ref, out_dir, fmi_version)` would build (no FMU, or one from other sources)."""
    if _fmi3(ref, fmi_version):
        return _build_fmi3().needs_build(ref, out_dir)
    target, digest = _target(ref, out_dir)
    return not (target.is_file() and built_hash(target) == digest)


def build_all(out_dir=None, fmi_version=2) -> dict:
    """Ensure every FMU of fmus_src is built; returns {name: path}."""
    return {name: ensure_fmu(name, out_dir, fmi_version) for name in available_fmus()}


def _build_fmi3():
    from aotv_cosim.fmu import build_fmi3  # it imports this module

    return build_fmi3


def _fmi3(ref, fmi_version) -> bool:
    """True when `ref` is built as FMI 3.0 (`build_fmi3.resolved_version`)."""
    return (fmi_version is not None or is_source_path(ref)) and _build_fmi3().resolved_version(ref, fmi_version) == 3


def _pythonfmu_build(source: Path, tmp: Path) -> Path:
    name = source.stem
    stage = tmp / "stage" / "aotv_cosim"
    for path in _runtime_files():
        dest = stage / path.relative_to(PACKAGE_DIR)
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(path, dest)
    saved_path = list(sys.path)
    try:
        # canGetAndSetFMUstate: AotvSlave snapshots its state (fmu/slave.py); not serializable
        return FmuBuilder.build_FMU(source, dest=tmp / f"{name}.fmu",
                                    project_files=[stage], canGetAndSetFMUstate=saves_state(source))
    except AotvError:
        raise
    except Exception as exc:  # pythonfmu raises anything from the user's module
        raise BuildError(f"pythonfmu failed: {exc}", file=str(source),
                         fix="fix the FMU module; run `aotv-cosim --debug build-fmus` for the traceback") from exc
    finally:
        sys.path[:] = saved_path


def runtime_package(digest: str) -> str:
    """Name of the bundled runtime package in the FMU built from sources of hash `digest`."""
    return f"aotv_cosim_{digest[:16]}"


def slave_module(name: str, digest: str) -> str:
    """Name of the module of fmus_src/<name>.py in the FMU built from sources of hash `digest`."""
    return f"{name}_{digest[:16]}"


_TOP_IMPORT = re.compile(r"^(\s*(?:from|import)\s+)(aotv_cosim|pythonfmu)(?=[\s.])", re.MULTILINE)


def renamed_imports(source: str, renames: dict, where: str) -> str:
    """`source` with its absolute imports of the top-level packages in `renames` ({old: new})
    rewritten; a BuildError if an import of them is left (one the line-start rewrite cannot see)."""
    text = _TOP_IMPORT.sub(lambda m: m.group(1) + renames[m.group(2)], source)
    for node in ast.walk(ast.parse(text)):
        names = [node.module or ""] if isinstance(node, ast.ImportFrom) and not node.level else \
            [alias.name for alias in node.names] if isinstance(node, ast.Import) else []
        if any(n.split(".")[0] in renames for n in names):
            raise BuildError(f"an import of {', '.join(names)} at line {node.lineno} cannot be renamed",
                             file=where, fix="write it as `from package.module import name` on one line")
    return text


def isolate(members: dict, name: str, digest: str) -> dict:
    """The FMU's archive members with its runtime under names of its own (module docstring):
    resources/aotv_cosim -> resources/<runtime_package>, resources/pythonfmu -> inside it,
    resources/<name>.py -> resources/<slave_module>.py (slavemodule.txt names it), and the
    imports of the bundled modules and the FMU's module rewritten to match."""
    package, module = runtime_package(digest), slave_module(name, digest)
    renames = {"aotv_cosim": package, "pythonfmu": f"{package}.pythonfmu"}
    moved = {"resources/aotv_cosim/": f"resources/{package}/",
             "resources/pythonfmu/": f"resources/{package}/pythonfmu/"}
    out = {}
    for member, data in members.items():
        prefix = next((p for p in moved if member.startswith(p)), None)
        if prefix is not None:
            target = moved[prefix] + member[len(prefix):]
        elif member == f"resources/{name}.py":
            target = f"resources/{module}.py"
        else:
            target = member
        if member == "resources/slavemodule.txt":
            data = module.encode()
        elif target.endswith(".py") and prefix != "resources/pythonfmu/" and target.startswith("resources/"):
            data = renamed_imports(data.decode(), renames, member).encode()
        out[target] = data
    return out


def _rewrite_reproducibly(raw: Path, out: Path, digest: str) -> None:
    with zipfile.ZipFile(raw) as src:
        members = {info.filename: src.read(info) for info in src.infolist() if not info.is_dir()}
    members = isolate(members, raw.stem, digest)
    members["modelDescription.xml"] = _reproducible_description(members["modelDescription.xml"], digest)
    members[TOKEN_FILE] = (ElementTree.fromstring(members["modelDescription.xml"]).get("guid") + "\n").encode()
    fmu_native.patch_linux_binary(members, raw.stem)
    members[BUILD_INFO] = (digest + "\n").encode()
    write_reproducible_zip(out, members)


def write_reproducible_zip(out: Path, members: dict) -> None:
    """Write {name: bytes} to the zip `out` in sorted order with a fixed date and mode, so the
    same members always give the same bytes (FMU and SSP archives)."""
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED) as dst:
        for name in sorted(members):
            info = zipfile.ZipInfo(name, date_time=ZIP_DATE)
            info.external_attr = 0o644 << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            dst.writestr(info, members[name])


def _reproducible_description(xml: bytes, digest: str) -> bytes:
    """Drop the generation date, state every variability, derive the GUID from sources and XML.

    pythonfmu leaves out the variability of inputs and outputs (FMI 2.0's default, continuous);
    it is written out so that tools which do not apply the default still show it.
    """
    root = ElementTree.fromstring(xml)
    root.attrib.pop("generationDateAndTime", None)
    for var in root.iter("ScalarVariable"):
        if "variability" not in var.attrib:
            var.set("variability", "continuous" if var.find("Real") is not None else "discrete")
    root.set("guid", "")
    ElementTree.indent(root, space="  ")
    body = ElementTree.tostring(root, encoding="unicode")
    guid = uuid.UUID(bytes=hashlib.sha256((digest + body).encode()).digest()[:16], version=5)
    root.set("guid", "{" + str(guid) + "}")
    out = io.BytesIO()
    ElementTree.ElementTree(root).write(out, encoding="UTF-8", xml_declaration=True)
    return out.getvalue() + b"\n"


def _validate(fmu: Path, source: Path) -> None:
    from fmpy.validation import validate_fmu

    problems = validate_fmu(str(fmu))
    if problems:  # in a user's source (a class declaring no variable) it is bad input, in fmus_src a bug
        error = BuildError if source.parent == fmus_src_dir() else InputError
        raise error("fmpy validate: " + " | ".join(problems),
                    file=str(source), entry="modelDescription.xml",
                    fix="declare every variable through AotvSlave.parameter/input/output")
