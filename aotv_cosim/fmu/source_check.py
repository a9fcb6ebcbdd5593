"""An FMU source imported once, in a child process with a time limit, before it is built.

A user's FMU source is code of theirs that this package runs to build it: importing the module
and instantiating its class (pythonfmu writes the modelDescription from an instance). That code
may hang, call ``sys.exit`` or ``os._exit``, crash the interpreter or have import-time side
effects. So `inspect_source` runs it once, in a child Python (`main`), and gets back as data
(`SourceClass`) all the build needs: the FMU class's name, whether it derives from AotvSlave,
and its modelDescription. Whatever goes wrong comes back as one error naming the file and, where
known, the line: an exception (its line in the source), ``sys.exit`` and ``os._exit`` (the line
of the call), a crash (the signal, and the line from the child's fault dump), and a child still
running after `IMPORT_TIME_LIMIT` seconds (the line it was stuck at, from the same dump; it and
every process it started are killed). The child writes no bytecode (no ``__pycache__`` beside
the source), reads no standard input, and writes its output to a file of at most `OUTPUT_LIMIT`
bytes whose tail is quoted when it ends without a report.

The rules the class is held to (one FMU class per file, the one the FMU's runtime will
instantiate) are checked in the child (`fmu_class`). A pythonfmu3 class (Fmi3SlaveBase) is found
and described the same way (`SourceClass.kind`): its FMI 3.0 FMU is then assembled from what the
child reported, as for a pythonfmu class, so no build imports a user's source in its own process.
"""

import contextlib
import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import traceback
from dataclasses import dataclass
from pathlib import Path

from aotv_cosim.errors import BuildError, InputError

IMPORT_TIME_LIMIT = 60.0
"""Seconds an FMU source may take to be imported, its class instantiated and its modelDescription
written, in the child process: a hang (an
endless loop at import or in ``__init__``) is refused after this. The slowest shipped source
takes 0.5 s (EntryTrackingGuidance, which solves its nominal when instantiated)."""
GRACE = 5.0
"""Seconds the parent waits beyond IMPORT_TIME_LIMIT for the child's own fault dump and exit
before killing it."""
OUTPUT_LIMIT = 16 * 2**20
"""Bytes the child may write to any file, its output file (stdout and stderr) among them: a
source that prints without end gets OSError (EFBIG, RLIMIT_FSIZE) at the write past it, reported
with its line like any exception."""
_QUOTED = 400
"""Characters of the child's output quoted in an error when it ended without a report."""


@dataclass(frozen=True)
class SourceClass:
    """What the child found in an FMU source."""

    class_name: str
    """The FMU class, the one concrete Fmi2Slave (or pythonfmu3 Fmi3SlaveBase) subclass the source
    defines."""
    model_identifier: str
    """Its modelName (pythonfmu's modelIdentifier: the binary's name)."""
    aotv_slave: bool
    """True if it derives from AotvSlave: it saves its FMU state and holds its do_step to the
    step contract itself."""
    model_description: str
    """pythonfmu's (or pythonfmu3's) modelDescription of an instance (XML text), before the build
    completes it."""
    kind: str = "pythonfmu"
    """"pythonfmu" for an Fmi2Slave class, "pythonfmu3" for an Fmi3SlaveBase one."""


def inspect_source(source: Path, ours: bool = False) -> SourceClass:
    """Import `source` once in a child process and return its `SourceClass`. A failure raises
    InputError naming the file (BuildError for a source of this package, `ours`)."""
    error = BuildError if ours else InputError
    with tempfile.TemporaryDirectory(prefix="aotv_source_") as tmp:
        report, log = Path(tmp) / "report.json", Path(tmp) / "output.txt"
        status, timed_out = _run_child(source, report, log)
        if report.is_file():
            found = json.loads(report.read_text())
            if "error" not in found:
                return SourceClass(**found)
            raise error(found["error"], file=str(source), entry=found["entry"], fix=found["fix"])
        output = log.read_text(errors="replace") if log.is_file() else ""
    raise error(_ended(status, timed_out, output), file=str(source), entry=_line(_dumped_line(output, source)),
                fix="fix the source; `python " + source.name + "` runs it alone")


def _line(line):
    return f"line {line}" if line else None


def _run_child(source: Path, report: Path, log: Path):
    """Run `main` in a child Python on `source`; (its exit status, whether it was killed at the
    time limit). The child is a session of its own: it and every process it started are killed
    when it ends, fails to end in time, or the parent is interrupted."""
    package_parent = str(Path(__file__).resolve().parents[2])
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1",
               PYTHONPATH=os.pathsep.join(p for p in (package_parent, os.environ.get("PYTHONPATH")) if p))
    code = "import sys; del sys.path[0]; from aotv_cosim.fmu.source_check import main; main()"
    with open(log, "wb") as output:
        child = subprocess.Popen([sys.executable, "-B", "-c", code, str(source), str(report), repr(IMPORT_TIME_LIMIT)],
                                 stdin=subprocess.DEVNULL, stdout=output, stderr=subprocess.STDOUT, env=env,
                                 start_new_session=True)
        try:
            return child.wait(timeout=IMPORT_TIME_LIMIT + GRACE), False
        except subprocess.TimeoutExpired:
            return None, True
        finally:
            _kill_group(child)


def _kill_group(child) -> None:
    """Kill the child's process group (the child and what it started; the child alone where
    there are no process groups) and reap the child."""
    with contextlib.suppress(ProcessLookupError, PermissionError):
        if hasattr(os, "killpg"):
            os.killpg(child.pid, signal.SIGKILL)
        else:
            child.kill()
    child.wait()


def _ended(status, timed_out: bool, output: str) -> str:
    """The cause of a child that ended without a report."""
    if timed_out or "Timeout (" in output:
        return (f"importing it, instantiating its class and writing its modelDescription took more than "
                f"{IMPORT_TIME_LIMIT:g} s (an endless loop?); the child process was killed")
    if status is not None and status < 0:
        try:
            name = signal.Signals(-status).name
        except ValueError:
            name = f"signal {-status}"
        cause = f"the child process importing it was killed by {name}"
    else:
        cause = f"the child process importing it ended with status {status} before it reported"
    own = re.split(r"\n(?:Current thread|Thread) 0x", output)[0]  # without the fault dump's frames
    tail = " ".join(own.split())[-_QUOTED:]
    return f"{cause}: {tail}" if tail else cause


def _dumped_line(output: str, source: Path):
    """The line of `source` in the innermost frame of a fault dump (faulthandler's format, most
    recent call first) in the child's output, or None."""
    for match in re.finditer(r'File "(?P<file>[^"]+)", line (?P<line>\d+)', output):
        if Path(match["file"]) == source:
            return int(match["line"])
    return None


# ---- the child --------------------------------------------------------------------------------
def main(argv=None) -> None:
    """The child: import the source (argv[0]) once, find its FMU class, instantiate it, write the
    `SourceClass` (or the error) as JSON to argv[1]; fault dump and exit after argv[2] seconds."""
    import faulthandler

    source, report, limit = argv or sys.argv[1:4]
    source, report = Path(source), Path(report)
    sys.dont_write_bytecode = True
    _limit_output()
    faulthandler.enable()
    faulthandler.dump_traceback_later(float(limit), exit=True)
    real_exit = _report_os_exit(source, report)
    try:
        found = _inspect(source)
    except _SourceProblem as problem:
        found = {"error": problem.cause, "entry": problem.entry, "fix": problem.fix}
    faulthandler.cancel_dump_traceback_later()
    _write(report, found)
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):  # a stream the source replaced or closed
            stream.flush()
    real_exit(0)  # no wait for threads the source started, no atexit handler of its own


def _limit_output() -> None:
    """At most OUTPUT_LIMIT bytes in any file this process writes (its output among them)."""
    try:
        import resource
    except ImportError:  # not on Windows
        return
    hard = resource.getrlimit(resource.RLIMIT_FSIZE)[1]
    limit = OUTPUT_LIMIT if hard == resource.RLIM_INFINITY else min(OUTPUT_LIMIT, hard)
    resource.setrlimit(resource.RLIMIT_FSIZE, (limit, hard))


def _write(report: Path, found: dict) -> None:
    partial = report.with_suffix(".part")
    partial.write_text(json.dumps(found))
    os.replace(partial, report)


def _report_os_exit(source: Path, report: Path):
    """Make os._exit report the line of `source` that called it before the process ends; returns
    the real os._exit."""
    real_exit = os._exit

    def reporting_exit(status):
        line = _line_of(traceback.extract_stack(sys._getframe(1)), source)
        _write(report, {"error": f"it called os._exit({status!r}) while being imported or instantiated",
                        "entry": _line(line), "fix": "an FMU source must not end the process; remove the call"})
        real_exit(status)
    os._exit = reporting_exit
    return real_exit


class _SourceProblem(Exception):
    """What is wrong with the source: its cause, where (line N, or `entry` when no line is
    known: "(top level)", "(whole file)"), and the fix."""

    def __init__(self, cause, line=None, fix="fix the source", entry=None):
        super().__init__(cause)
        self.cause, self.entry, self.fix = cause, _line(line) or entry, fix


def _line_of(frames, source: Path):
    """The line of the innermost of `frames` (a traceback.StackSummary) in `source`, or None."""
    lines = [f.lineno for f in frames if Path(f.filename) == source]
    return lines[-1] if lines else None


def _raised(what: str, exc: BaseException, source: Path) -> _SourceProblem:
    """The problem of an exception (SystemExit included) raised by `source` while `what`."""
    line = _line_of(traceback.extract_tb(exc.__traceback__), source)
    whole = None
    if isinstance(exc, SyntaxError) and Path(exc.filename or source) == source:
        line = exc.lineno  # raised while compiling: the line is on the error, not in a frame
        whole = "(whole file)"
    if isinstance(exc, SystemExit):
        return _SourceProblem(f"{what} called sys.exit({exc.code!r})", line,
                              "an FMU source must not end the process; remove the call")
    text = " ".join(f"{type(exc).__name__}: {exc}".split())
    return _SourceProblem(f"{what} raised {text}", line,
                          f"fix the source (run `python {source.name}` to see the traceback)", whole)


def decode_source(data: bytes):
    """(text, encoding) of Python source bytes, decoded per PEP 263 (UTF-8 unless a coding line
    or a BOM says otherwise). SyntaxError for an unknown declared encoding, UnicodeDecodeError
    for bytes the encoding does not allow (CPython compiles such bytes in a comment, but refuses
    the file as a script)."""
    import io
    import tokenize

    encoding, _ = tokenize.detect_encoding(io.BytesIO(data).readline)
    return data.decode(encoding), encoding


def _check_encoding(source: Path) -> None:
    """_SourceProblem, with the line, for a source that does not decode per PEP 263."""
    data = source.read_bytes()
    fix = ("save the file as UTF-8, or declare its encoding on its first or second line "
           "(`# -*- coding: latin-1 -*-`, PEP 263)")
    try:
        decode_source(data)
    except SyntaxError as exc:  # tokenize's: an unknown or conflicting declaration, or line 1 not UTF-8
        if "unknown encoding" not in exc.msg:
            try:
                data.decode("utf-8")
            except UnicodeDecodeError as bad:
                raise _undecodable(data, bad, fix) from None
        raise _SourceProblem(f"SyntaxError: {exc.msg}", exc.lineno, fix, "(whole file)") from None
    except UnicodeDecodeError as exc:
        raise _undecodable(data, exc, fix) from None


def _undecodable(data: bytes, exc: UnicodeDecodeError, fix: str) -> _SourceProblem:
    return _SourceProblem(f"SyntaxError: byte 0x{data[exc.start]:02x} is not valid {exc.encoding}, the file's "
                          "encoding (UTF-8 unless a coding line declares another)",
                          data[:exc.start].count(b"\n") + 1, fix)


def _inspect(source: Path) -> dict:
    """The child's work: the `SourceClass` fields of `source`, or a _SourceProblem."""
    _check_encoding(source)
    try:
        cls = fmu_class(source)
    except _SourceProblem:
        raise
    except BaseException as exc:  # the source may raise anything, SystemExit included
        raise _raised("importing it", exc, source) from None
    try:
        instance = cls(instance_name="dummyInstance", resources=str(source.parent))
        model_description = instance.to_xml()
        name = instance.modelName
    except BaseException as exc:  # the source may raise anything, SystemExit included
        raise _raised(f"instantiating {cls.__name__}", exc, source) from None
    from xml.etree.ElementTree import tostring

    from aotv_cosim.fmu.slave import AotvSlave

    return {"class_name": cls.__name__, "model_identifier": str(name), "aotv_slave": issubclass(cls, AotvSlave),
            "model_description": tostring(model_description, encoding="unicode"),
            "kind": "pythonfmu3" if _fmi3_base() is not None and issubclass(cls, _fmi3_base()) else "pythonfmu"}


def load_module(source: Path):
    """Import `source` as a module of its own (not left in sys.modules): the module object."""
    import importlib.util

    name = "_aotv_fmu_source_" + re.sub(r"\W", "_", source.stem)  # a dot in the file name is no package
    spec = importlib.util.spec_from_file_location(name, source)
    assert spec is not None and spec.loader is not None  # a .py file has a spec and a source loader
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses and pickling look the module up while it runs
    try:
        spec.loader.exec_module(module)
    finally:
        sys.modules.pop(name, None)
    return module


def _fmi3_base():
    """pythonfmu3's Fmi3SlaveBase, or None where pythonfmu3 is not installed."""
    try:
        from pythonfmu3 import Fmi3SlaveBase
    except ImportError:
        return None
    return Fmi3SlaveBase


def fmu_class(source: Path) -> type:
    """Import `source` (`load_module`) and return its FMU class: the one concrete Fmi2Slave (or
    pythonfmu3 Fmi3SlaveBase) subclass it defines, which must also be the class the FMU's runtime
    instantiates (the C wrappers and the direct calls take the class of the module with Fmi2Slave,
    or for FMI 3.0 Fmi3SlaveBase, deepest in its method resolution order). _SourceProblem for
    none, several, or another class taken."""
    import inspect

    from pythonfmu import Fmi2Slave

    bases = tuple(b for b in (Fmi2Slave, _fmi3_base()) if b is not None)
    module = load_module(source)
    defined = [c for c in vars(module).values() if inspect.isclass(c) and issubclass(c, bases)
               and c not in bases and c.__module__ == module.__name__ and not inspect.isabstract(c)]
    if not defined:
        raise _SourceProblem("defines no concrete FMU class", None, entry="(top level)",
                             fix="define one subclass of aotv_cosim.laws.AotvSlave (or of pythonfmu.Fmi2Slave, or "
                             "pythonfmu3's Fmi3Slave) with do_step and every abstract method")
    if len(defined) > 1:
        at = _class_lines(source)
        lines = ", ".join(f"{c.__name__} (line {at[c.__name__]})" if c.__name__ in at else c.__name__
                          for c in defined)
        raise _SourceProblem(f"defines {len(defined)} FMU classes: {lines}", None,
                             "keep one FMU class per file (a shared base may stay, made abstract)", "(top level)")
    taken, law = _runtime_class(module), defined[0]
    assert taken is not None  # law itself derives from Fmi2Slave or Fmi3SlaveBase
    if taken is not law:
        fix = (f"derive {law.__name__} from {taken.__name__}, or move {taken.__name__} to another module"
               if taken.__module__ == module.__name__ else
               f"import the module instead of the class (`import aotv_cosim.laws as laws`, then "
               f"`laws.{taken.__name__}`), or derive {law.__name__} from it")
        raise _SourceProblem(f"the FMU would instantiate {taken.__name__}, not {law.__name__}: the FMU's runtime "
                             "takes the first class of the module deepest below Fmi2Slave", None, fix, "(top level)")
    return law


def _class_lines(source: Path) -> dict:
    """{class name: line of its definition} of the top-level classes of `source`."""
    import ast

    return {node.name: node.lineno for node in ast.parse(source.read_bytes()).body if isinstance(node, ast.ClassDef)}


def _runtime_class(module) -> type | None:
    """The class the FMU's runtime takes from `module`: the first one with the class named
    Fmi2Slave (or, as the FMI 3.0 wrapper also looks, Fmi3SlaveBase) deepest in its method
    resolution order (fmi_core.c, direct_instance.slave_class)."""
    best, deepest = None, 0
    for value in vars(module).values():
        if isinstance(value, type):
            depth = next((i for i in range(len(value.__mro__) - 1, 0, -1)
                          if value.__mro__[i].__name__ in ("Fmi2Slave", "Fmi3SlaveBase")), 0)
            if depth > deepest:
                best, deepest = value, depth
    return best
