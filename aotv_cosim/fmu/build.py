"""Build the FMUs of ``fmus_src``, or a user's FMU source file from any folder, with pythonfmu:
content-hash cache, compliant, reproducible.

An FMU is named by its source (`fmu_source`): a name of fmus_src, or a path ending in .py (a
user's law, see docs/writing-a-guidance-law.md). The source is imported once, in a child process
with a time limit (`check_source`, `aotv_cosim.fmu.source_check`): the build never runs the
source's code in its own process, and gets back as data the FMU class, whether it is an
AotvSlave (canGetAndSetFMUstate is declared true only for one, whose state snapshot the runtime
provides) and pythonfmu's modelDescription; a failure is one error naming the file and line.
The archive is then assembled as pythonfmu's builder assembles it (`_pythonfmu_members`), and
the modelDescription completed where pythonfmu leaves out what FMI 2.0 requires
(`_completed_structure`: InitialUnknowns, variabilities), so that a plain pythonfmu Fmi2Slave
class builds too; its do_step is held to the step contract an AotvSlave's is
(`_contract_hook`).

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
(`fmu_native`), and the wrapper it holds is recorded (`WRAPPER_INFO`, `built_wrapper`). Finally
`fmpy validate` must report no problem. With ``fmi_version=3`` the FMU is built as FMI 3.0
instead (`aotv_cosim.fmu.build_fmi3`, also for a pythonfmu3 class).
"""

import ast
import contextlib
import difflib
import functools
import hashlib
import io
import os
import re
import shutil
import subprocess
import tempfile
import uuid
import zipfile
from itertools import chain
from pathlib import Path
from xml.etree import ElementTree

import pythonfmu

from aotv_cosim.errors import BuildError, InputError
from aotv_cosim.fmu import native as fmu_native
from aotv_cosim.fmu import source_check
from aotv_cosim.paths import regular_file, resolved

PACKAGE_DIR = Path(__file__).resolve().parents[1]
RUNTIME = ("__init__.py", "laws.py", "fmu/__init__.py", "fmu/slave.py", "fmu/actuator_slave.py",
           "fmu/guidance_slave.py", "fmu/bank_guidance.py", "fmu/vehicle_slave.py", "physics", "guidance")
"""Paths inside aotv_cosim that every FMU bundles (they import numpy, scipy and pythonfmu only)."""
RUNTIME_PATTERNS = ("*.py", "*.csv")
"""Files bundled from the RUNTIME folders: modules and the data tables they read beside them."""
BUILD_INFO = "resources/aotv_cosim_build.txt"
"""Archive member holding the source hash an FMU was built from."""
TOKEN_FILE = "resources/aotv_cosim_guid.txt"
"""Archive member holding the GUID (FMI 2.0) or instantiationToken (FMI 3.0) the FMU was built with,
one line: the lean wrapper refuses to instantiate with another (aotv_cosim/fmu/fmi_core.c)."""
WRAPPER_INFO = "resources/aotv_cosim_wrapper.txt"
"""Archive member naming the FMI wrapper of the FMU's Linux binary: "lean" (fmi2_lean.c) or
"stock" (pythonfmu's; also where the binary is not patched: no compiler, not Linux)."""
PYTHONFMU_DIR = Path(pythonfmu.__file__).resolve().parent
"""pythonfmu's package: its modules are bundled into every FMU, its binaries are the FMUs'."""
ZIP_DATE = (1980, 1, 1, 0, 0, 0)
BUILD_HOOKS: list = []
"""Callables hook(name, stage) told of every build `ensure_fmu` makes: stage "start" before it,
"done" after (the command line's progress, aotv_cosim.fmu.build_progress)."""
BUILD_FORMAT = ("6: explicit variability, Linux binary loads in C hosts, FMU state get/set, runtime "
                "under a name of its own, GUID in resources, source inspected in a child, wrapper "
                "recorded, plain pythonfmu classes completed and held to the step contract")
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
        fix = "give the path of a Python file defining one FMU class (see docs/writing-a-guidance-law.md)"
        try:
            path = resolved(ref, what="FMU source (.py)")
            regular_file(path, what="FMU source (.py)")
        except InputError as exc:
            raise InputError(exc.cause, file=str(ref), fix=fix) from None
        return path
    if ref not in available_fmus():  # a misspelt name is the user's input
        raise InputError(f"no FMU named {ref!r} in this package", file=str(ref),
                         fix=_unknown_name_fix(ref, "a .py FMU source"))
    return fmus_src_dir() / f"{ref}.py"


def _unknown_name_fix(ref, also: str) -> str:
    """The fix of an FMU name of no FMU of fmus_src: close names, `also`, the names."""
    names = available_fmus()
    close = difflib.get_close_matches(str(ref), names, n=3)
    hint = f"did you mean {' or '.join(close)}? " if close else ""
    return f"{hint}give {also} or one of {', '.join(names)}"


def is_ours(source: Path) -> bool:
    """True if `source` is a file of fmus_src (a failure to build it is this package's bug, a
    BuildError; in a user's source it is bad input, an InputError)."""
    return source.parent == fmus_src_dir()


def check_source(source: Path) -> source_check.SourceClass:
    """Import the FMU source `source` once, in a child process with a time limit, and return
    what the build needs of its FMU class (`source_check.inspect_source`): one error naming the
    file and line for a source that fails to import, hangs, exits, defines no FMU class or two."""
    return source_check.inspect_source(source, ours=is_ours(source))


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
    if module_name(source.stem) != source.stem:  # its module is renamed: not the FMU built before that was
        digest.update(f"module {module_name(source.stem)}\n".encode())
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
    if not is_source_path(ref) and ref not in available_fmus():
        raise InputError(f"no FMU named {ref!r} in this package",
                         fix=_unknown_name_fix(ref, "a path to a .fmu file or a .py FMU source (relative to the "
                                                    "wiring file)"))
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
    found = check_source(source)  # a broken source is one error line, before any progress is shown
    if found.kind == "pythonfmu3":  # named apart in its class statement: resolved_version did not see it
        raise InputError(f"{found.class_name} is a pythonfmu3 class, which builds as FMI 3.0 only", file=str(source),
                         fix="build it with --fmi 3, or write it on pythonfmu's Fmi2Slave")
    for hook in BUILD_HOOKS:
        hook(name, "start")
    target.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="aotv_build_") as tmp:
        members = _pythonfmu_members(source, found)
        _contract_hook(members, source, found)
        staged = Path(tmp) / "final.fmu"
        _rewrite_reproducibly(members, staged, digest, source, found)
        _validate(staged, source)
        install(staged, target)
    for hook in BUILD_HOOKS:
        hook(name, "done")
    return target


def install(staged: Path, target: Path) -> None:
    """Put the built archive `staged` at `target` whole or not at all: renamed, or copied beside
    `target` and renamed where they are on other disks. A disk that cannot take it (full, read-only)
    leaves no partial file and is an InputError (as export-ssp's archive and an unwritable --out are)."""
    part = target.with_name(f".{target.name}.{os.getpid()}.part")
    try:
        if staged.stat().st_dev == target.parent.stat().st_dev:
            os.replace(staged, target)
        else:
            shutil.copyfile(staged, part)
            os.replace(part, target)
    except OSError as exc:
        with contextlib.suppress(OSError):
            part.unlink(missing_ok=True)
        raise InputError(f"cannot write {target.name}: {exc.strerror or exc}", file=target.parent, entry="--out",
                    fix="free space on that disk or choose another --out (the FMU cache: $AOTV_COSIM_CACHE)") from None


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


def _pythonfmu_members(source: Path, found) -> dict:
    """The archive members {name: bytes} pythonfmu 0.7's builder writes for the FMU class `found`
    (`source_check.SourceClass`) of `source`, with this package's runtime as its project files:
    the module and slavemodule.txt naming it, pythonfmu's modules and this package's runtime under
    resources/, pythonfmu's binaries named by the model identifier, and the modelDescription with
    canGetAndSetFMUstate true for an AotvSlave (its snapshot is the runtime's; not serializable)."""
    members = {f"resources/{source.name}": source.read_bytes(), "resources/slavemodule.txt": source.stem.encode()}
    for path in sorted(PYTHONFMU_DIR.glob("*.py")):
        members[f"resources/pythonfmu/{path.name}"] = path.read_bytes()
    for path in _runtime_files():
        members[f"resources/aotv_cosim/{path.relative_to(PACKAGE_DIR).as_posix()}"] = path.read_bytes()
    binaries = PYTHONFMU_DIR / "resources" / "binaries"
    for path in sorted(chain(*(binaries.rglob(f"*.{ext}") for ext in ("dll", "so", "dylib")))):
        folder = path.relative_to(binaries).parent.as_posix()
        members[f"binaries/{folder}/{found.model_identifier}{path.suffix}"] = path.read_bytes()
    root = ElementTree.fromstring(found.model_description)
    co_simulation = root.find("CoSimulation")
    assert co_simulation is not None  # pythonfmu writes it
    co_simulation.set("canGetAndSetFMUstate", str(found.aotv_slave).lower())
    members["modelDescription.xml"] = ElementTree.tostring(root, encoding="UTF-8")
    return members


CONTRACT_HOOK = ("\n\nfrom aotv_cosim.fmu.slave import enforce_step_contract as _aotv_enforce_step_contract  "
                 "# added by aotv-cosim\n_aotv_enforce_step_contract({name})\n")
"""Lines appended to the module of a plain pythonfmu class in its FMU (`_contract_hook`)."""


def _contract_hook(members: dict, source: Path, found) -> None:
    """Hold the do_step of a plain pythonfmu or pythonfmu3 class (not an AotvSlave, whose own
    definition does) to the step contract in every host: `CONTRACT_HOOK` appended to its module in
    the FMU, after the author's last line (their line numbers unchanged)."""
    if found.aotv_slave:
        return
    member = f"resources/{source.name}"
    text, encoding = source_check.decode_source(members[member])
    members[member] = (text.rstrip("\n") + CONTRACT_HOOK.format(name=found.class_name)).encode(encoding)


def runtime_package(digest: str) -> str:
    """Name of the bundled runtime package in the FMU built from sources of hash `digest`."""
    return f"aotv_cosim_{digest[:16]}"


def slave_module(name: str, digest: str) -> str:
    """Name of the module of fmus_src/<name>.py (or of a user's <name>.py) in the FMU built from
    sources of hash `digest`: `module_name(name)` and the hash."""
    return f"{module_name(name)}_{digest[:16]}"


def module_name(stem: str) -> str:
    """A module name for a source file named `stem`.py: every character that cannot stand in a
    Python identifier replaced by "_" (a file law.v2.py would be imported as the module v2 of a
    package law, and its FMU could never be instantiated)."""
    return re.sub(r"\W", "_", stem)


_TOP_IMPORT = re.compile(r"^(\s*(?:from|import)\s+)(aotv_cosim|pythonfmu)(?=[\s.])", re.MULTILINE)


def renamed_imports(source: str, renames: dict, where: str) -> str:
    """`source` with its absolute imports of the top-level packages in `renames` ({old: new})
    rewritten; a BuildError if an import of them is left (one the line-start rewrite cannot see)."""
    text = _TOP_IMPORT.sub(lambda m: m.group(1) + renames[m.group(2)], source)
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, ast.ImportFrom) and not node.level:
            names = [node.module or ""]
        elif isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        else:
            continue
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
            text, encoding = source_check.decode_source(data)  # a user's module may declare its encoding
            data = renamed_imports(text, renames, member).encode(encoding)
        out[target] = data
    return out


def _rewrite_reproducibly(members: dict, out: Path, digest: str, source: Path, found) -> None:
    """Write the archive `out` from pythonfmu's `members`: the runtime isolated, the description
    completed and reproducible, the Linux binary patched (`_patched_binary`), the build recorded."""
    members = isolate(members, source.stem, digest)
    members["modelDescription.xml"] = _reproducible_description(members["modelDescription.xml"], digest)
    members[TOKEN_FILE] = (ElementTree.fromstring(members["modelDescription.xml"]).attrib["guid"] + "\n").encode()
    members[WRAPPER_INFO] = (_patched_binary(members, source, found) + "\n").encode()
    members[BUILD_INFO] = (digest + "\n").encode()
    write_reproducible_zip(out, members)


def _patched_binary(members: dict, source: Path, found) -> str:
    """Patch the Linux binary in `members` (`fmu_native.patch_linux_binary`) and return the
    wrapper it holds ("lean" or "stock"). A compiler or patchelf that fails is a build error
    with its message (InputError for a user's source: the build of it fails), never a traceback."""
    try:
        fmu_native.patch_linux_binary(members, found.model_identifier)
    except (OSError, subprocess.CalledProcessError) as exc:
        if isinstance(exc, subprocess.CalledProcessError):
            said = " ".join((exc.stderr or b"").decode(errors="replace").split())[-300:]
            cause = f"{Path(exc.cmd[0]).name} exited with status {exc.returncode}" + (f": {said}" if said else "")
        else:
            cause = str(exc)
        error = BuildError if is_ours(source) else InputError
        raise error(f"building the FMU's native wrapper failed: {cause}",
                    file=str(source), entry=f"binaries/linux64/{found.model_identifier}.so",
                    fix=f"check the C compiler (gcc) and patchelf, or set {fmu_native.WRAPPER_VARIABLE}=stock "
                        "(pythonfmu's wrapper, no compiler needed)") from None
    return fmu_native.wrapper() if fmu_native.patch_reason() is None else "stock"


def built_wrapper(fmu: Path):
    """The FMI wrapper of an FMU built here ("lean" or "stock", `WRAPPER_INFO`), or None for an
    FMU from elsewhere (or built before the wrapper was recorded)."""
    try:
        stat = os.stat(fmu)
    except OSError:
        return None
    return _recorded_wrapper(str(fmu), stat.st_size, stat.st_mtime_ns)


@functools.lru_cache(maxsize=256)
def _recorded_wrapper(path: str, size: int, mtime: int):
    try:
        with zipfile.ZipFile(path) as archive:
            return archive.read(WRAPPER_INFO).decode().strip()
    except (OSError, KeyError, zipfile.BadZipFile):
        return None


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
    """Drop the generation date, state every variability, complete the model structure
    (`_completed_structure`), derive the GUID from sources and XML.

    pythonfmu leaves out the variability of inputs and outputs (FMI 2.0's default, continuous,
    which an Integer, Boolean or String cannot have); it is written out so that tools which do
    not apply the default still show it.
    """
    root = ElementTree.fromstring(xml)
    root.attrib.pop("generationDateAndTime", None)
    for var in root.iter("ScalarVariable"):
        if "variability" not in var.attrib:
            var.set("variability", "continuous" if var.find("Real") is not None else "discrete")
    _completed_structure(root)
    root.set("guid", "")
    ElementTree.indent(root, space="  ")
    body = ElementTree.tostring(root, encoding="unicode")
    guid = uuid.UUID(bytes=hashlib.sha256((digest + body).encode()).digest()[:16], version=5)
    root.set("guid", "{" + str(guid) + "}")
    out = io.BytesIO()
    ElementTree.ElementTree(root).write(out, encoding="UTF-8", xml_declaration=True)
    return out.getvalue() + b"\n"


INITIAL_UNKNOWN = {"output", "calculatedParameter"}
"""Causalities whose variables are InitialUnknowns (FMI 2.0 sec. 2.2.8, co-simulation) unless
their `initial` is "exact"."""


def _completed_structure(root) -> None:
    """Write ModelStructure/InitialUnknowns where pythonfmu leaves it out (a plain Fmi2Slave
    class; an AotvSlave writes its own, with dependencies): every output and calculated
    parameter whose `initial` is not "exact" (the default, calculated), without dependencies
    (FMI 2.0: then it may depend on every known), in index order. fmpy validate requires it."""
    structure = root.find("ModelStructure")
    if structure is None or structure.find("InitialUnknowns") is not None:
        return
    unknowns = [str(i) for i, var in enumerate(root.find("ModelVariables").iter("ScalarVariable"), 1)
                if var.get("causality") in INITIAL_UNKNOWN and var.get("initial", "calculated") != "exact"]
    if not unknowns:
        return
    initial = ElementTree.Element("InitialUnknowns")
    for index in unknowns:
        ElementTree.SubElement(initial, "Unknown", index=index)
    position = 1 if structure.find("Outputs") is not None else 0  # Outputs, Derivatives, InitialUnknowns
    structure.insert(position + (structure.find("Derivatives") is not None), initial)


def _validate(fmu: Path, source: Path) -> None:
    from fmpy.validation import validate_fmu

    problems = validate_fmu(str(fmu))
    if problems:  # in a user's source (a class declaring no variable) it is bad input, in fmus_src a bug
        error = BuildError if is_ours(source) else InputError
        raise error("fmpy validate: " + " | ".join(problems),
                    file=str(source), entry="modelDescription.xml",
                    fix="declare every variable through AotvSlave.parameter/input/output")
