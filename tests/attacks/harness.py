"""How an attack case is run and judged (`tests/attacks/corpus.py` holds the cases).

A case is something a user can type or write, given to one face of the package: the command line
run in this process (`cli`), the Python API (`api`), or the command line as a process of its own
(`process`: signals, resource limits). Each runs in a sandbox folder: `home/` is the user's
folder, holding a file of theirs (`notes.txt`) and whatever the case's `setup` writes; the
temporary folder of the package (`tempfile`, `$TMPDIR`) is `systmp/`; the working folder is
`home/`. After the case, whatever it was, these must hold:

- the outcome expected: bad input is exit status 2 and one line `error: FILE: ENTRY: CAUSE; FIX`
  on stderr (the API: `InputError`, whose text is that line without `error: `), never exit 0,
  never exit 3 (a traceback); a valid input 0; a failed run 1; an interruption 128 + signal;
- no hang (each case has a time limit; `pytest-timeout` ends a test that passes it);
- no stray file: no `.part`, no `__pycache__` anywhere in the sandbox, nothing left in
  `systmp/`, and for bad input nothing new in the sandbox at all;
- nothing of the user's deleted or changed: every file there before the case is there after,
  with its bytes;
- no process left: this process has no child it did not have before (looked at for 3 s).
"""

import dataclasses
import hashlib
import os
import re
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from click.testing import CliRunner

from aotv_cosim.errors import InputError

ROOT = Path(__file__).resolve().parents[2]
PROGRESS = re.compile(r"^(|building.*|.*\|.*\[[0-9:]+.*\].*)$")
"""A line of progress on stderr (a build's message and bar, a tqdm bar): shown before a refusal that
comes after the work began (a disk that fills while an FMU is written); the error is the last line."""
LINE = re.compile(r"^error: (?P<file>.+?): (?P<rest>.+); (?P<fix>.+)$")
"""The one line of bad input: `error: FILE: [ENTRY: ]CAUSE; FIX` (FILE may hold ': ' only in
text like 'X (with --set)', ENTRY is optional where no entry applies)."""


@dataclasses.dataclass(frozen=True)
class Case:
    """One attack: `what` given to `face`, and the outcome expected."""

    name: str
    """Unique, short: the test id."""
    category: str
    """Its row of the table in docs/reliability.md."""
    face: str
    """"cli" (the command line in this process), "api" (a Python call) or "process" (the command
    line as a process of its own, for signals and resource limits)."""
    what: object
    """cli, process: the arguments (strings with {placeholders} of `Sandbox.names`); api: a
    callable of the Sandbox."""
    expect: str
    """"bad" (exit 2, InputError), "ok" (exit 0), "failed" (exit 1) or "interrupted" (128 + signal)."""
    fragments: tuple = ()
    """Texts the error line (bad) or the output (others) must hold ({placeholders} allowed)."""
    setup: Callable | None = None
    """setup(sandbox): writes the case's files into sandbox.home."""
    fmus: bool = False
    """Needs this package's FMUs built (the test is then marked integration)."""
    slow: bool = False
    """Too slow for the default suite (seconds of waiting): marked slow."""
    fixed: str = ""
    """What the package did before this case's fix (empty: the case held already)."""
    signals: tuple = ()
    """process: ((wait_for, signal), ...): each signal sent once wait_for(sandbox) is true."""
    limit: float = 120.0
    """Seconds the case may take."""
    import_limit: float | None = None
    """A shorter time limit for the import of a user's FMU source (`fmu.source_check`), s."""
    preexec: Callable | None = None
    """process: run in the child before the command (a resource limit)."""
    then: Callable | None = None
    """then(sandbox): more checks after the case."""


@dataclasses.dataclass
class Sandbox:
    """The folders of one case (module docstring) and the names its arguments may use."""

    root: Path
    extra: dict = dataclasses.field(default_factory=dict)
    """More names for the arguments, set by a setup (a server's address)."""

    @property
    def home(self) -> Path:
        return self.root / "home"

    @property
    def systmp(self) -> Path:
        return self.root / "systmp"

    @property
    def out(self) -> Path:
        return self.home / "out"

    @property
    def names(self) -> dict:
        scenarios = ROOT / "scenarios"
        return {"home": str(self.home), "out": str(self.out), "N": str(scenarios / "aotv_time_linear_nominal.json"),
                "W": str(scenarios / "systems" / "aotv_time_linear.json"),
                "MC": str(scenarios / "montecarlo_robust_density.json"), "SET": str(scenarios / "benchmark_seed000"),
                "P": str(scenarios / "benchmark_seed000" / "time_linear.json"), "TYPED": str(typed_fmu()),
                **self.extra}

    def path(self, text: str) -> str:
        """`text` with its {placeholders} of `names` filled in (other braces kept)."""
        names = self.names
        return re.sub(r"\{(\w+)\}", lambda m: names.get(m[1], m[0]), text)


def typed_fmu() -> Path:
    """The corpus's crafted FMU with typed variables (tests/data/corpus/make_archives.py)."""
    return ROOT / "tests" / "data" / "corpus" / "fmus" / "typed.fmu"


@dataclasses.dataclass
class Outcome:
    """What a case did: its exit status (the API: 2 for InputError, 0 for a return), stderr and
    stdout (the API: the error's text), the exception it raised if not the expected kind."""

    status: int
    stderr: str = ""
    stdout: str = ""
    value: object = None


def snapshot(root: Path) -> dict:
    """{relative path: what it is: a file by its content hash (a record by its text), a link by its
    target, a folder by its being there} of every entry under `root`."""
    found = {}
    for folder, dirs, files in os.walk(root):
        for name in dirs + files:
            path = Path(folder) / name
            info = path.lstat()
            if path.is_symlink():
                kept = ("link", os.readlink(path))
            elif path.is_dir():
                kept = ("folder",)  # its entries are compared, not its times
            elif path.is_file() and name == ".aotv-written":  # the record, read as it was then
                kept = ("file", path.read_text())
            elif path.is_file() and info.st_size <= 64 * 2**20:
                kept = ("file", hashlib.sha256(path.read_bytes()).hexdigest())
            else:
                kept = ("other", info.st_size, info.st_mtime_ns)
            found[str(path.relative_to(root))] = kept
    return found


def written_before(before: dict) -> set:
    """The entries of a `snapshot` that the package had written (listed in the `.aotv-written` of
    their folder, or a folder above), with those records and locks: a command may rewrite them."""
    ours = set()
    for name, kept in before.items():
        if Path(name).name == ".aotv-written" and kept[0] == "file":
            folder = Path(name).parent
            ours |= {str(folder / line) for line in kept[1].splitlines() if line}
            ours |= {name, str(folder / ".lock")}
    return {name for name in before if name in ours or any(str(p) in ours for p in Path(name).parents)}


def children() -> set:
    """Pids of this process's live children (not zombies), from /proc."""
    found = set()
    for task in Path(f"/proc/{os.getpid()}/task").iterdir():
        try:
            pids = (task / "children").read_text().split()
        except OSError:
            continue
        for pid in pids:
            try:
                state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
            except OSError:
                continue
            if state not in ("Z", "X"):
                found.add(int(pid))
    return found


def run_cli(args, sandbox: Sandbox) -> Outcome:
    from aotv_cosim.cli import main

    result = CliRunner().invoke(main, [sandbox.path(str(a)) for a in args])
    if result.exception is not None and not isinstance(result.exception, SystemExit):
        raise AssertionError(f"the command raised {result.exception!r}") from result.exception
    return Outcome(result.exit_code, result.stderr, result.stdout)


def run_api(call, sandbox: Sandbox) -> Outcome:
    try:
        value = call(sandbox)
    except InputError as exc:
        return Outcome(2, f"error: {exc}\n")
    return Outcome(0, value=value)


def run_process(case: Case, sandbox: Sandbox) -> Outcome:
    """`python -m aotv_cosim ARGS` in the sandbox, each of the case's signals sent once its
    condition holds; killed (and the case failed as a hang) after `case.limit` s."""
    env = dict(os.environ, PYTHONPATH=str(ROOT), TMPDIR=str(sandbox.systmp))
    # preexec_fn: a resource limit, set in the child before it runs
    child = subprocess.Popen([sys.executable, "-m", "aotv_cosim", *[sandbox.path(str(a)) for a in case.what]],
                             cwd=sandbox.home, env=env, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, start_new_session=True, preexec_fn=case.preexec)
    deadline = time.monotonic() + case.limit
    try:
        for ready, number in case.signals:
            while not ready(sandbox):
                if child.poll() is not None or time.monotonic() > deadline:
                    break
                time.sleep(0.05)
            if child.poll() is None:
                os.kill(child.pid, number)
        out, err = child.communicate(timeout=max(1.0, deadline - time.monotonic()))
    except subprocess.TimeoutExpired:
        os.killpg(child.pid, signal.SIGKILL)
        child.communicate()
        raise AssertionError(f"hung: still running after {case.limit:g} s") from None
    time.sleep(0.2)
    group = subprocess.run(["pgrep", "-g", str(child.pid)], capture_output=True, text=True, check=False).stdout.split()
    assert not group, f"processes left in the command's process group: {group}"
    return Outcome(child.returncode, err, out)


EXPECTED_STATUS = {"bad": 2, "ok": 0, "failed": 1}


def judge(case: Case, outcome: Outcome, sandbox: Sandbox) -> None:
    """Assert the outcome the case expects (module docstring)."""
    text = outcome.stderr + outcome.stdout
    assert "Traceback" not in text, text[-3000:]
    assert outcome.status != 3, text[-3000:]
    if case.expect == "interrupted":  # a second signal may meet the process as it exits: killed by it, output written
        allowed = {128 + signal.SIGINT, 128 + signal.SIGTERM} | ({-signal.SIGINT, -signal.SIGTERM}
                                                               if len(case.signals) > 1 else set())
        assert outcome.status in allowed, (outcome.status, text[-3000:])
    else:
        assert outcome.status == EXPECTED_STATUS[case.expect], (outcome.status, text[-3000:])
    fragments = [sandbox.path(f) for f in case.fragments]
    if case.expect == "bad":  # one line; several problems of one file (ValidationFailed): one line each
        lines = [line for line in outcome.stderr.strip().splitlines() if not PROGRESS.match(line)]
        assert lines and all(LINE.match(line) for line in lines), lines
        assert len(lines) == 1 or len({LINE.match(line)["file"] for line in lines}) == 1, lines
        for fragment in fragments:
            assert any(fragment in line for line in lines), (fragment, lines)
    else:
        for fragment in fragments:
            assert fragment in text, (fragment, text[-3000:])


def check_sandbox(case: Case, before: dict, after: dict, sandbox: Sandbox) -> None:
    """Nothing of the user's lost, no stray file, nothing left in the temporary folder, and for
    bad input nothing new."""
    ours = written_before(before)
    lost = [name for name, kept in before.items()
            if after.get(name) != kept and not name.startswith("systmp") and name not in ours]
    assert not lost, f"changed or deleted: {lost}"
    stray = [name for name in after if name.endswith((".part", ".tmp")) or "__pycache__" in Path(name).parts]
    assert not stray, f"stray files: {stray}"
    left = [p.name for p in sandbox.systmp.iterdir() if not p.name.startswith("pymp-")]
    assert not left, f"left in the temporary folder: {left}"
    if case.expect == "bad":
        new = sorted(set(after) - set(before))
        assert not new, f"bad input, yet written: {new}"


def run_case(case: Case, root: Path, monkeypatch) -> Outcome:
    """Run `case` in a sandbox under `root` and check everything (module docstring); what a setup
    put in `sandbox.extra["cleanups"]` (a mount) is undone after, however the case ends."""
    sandbox = Sandbox(root)
    sandbox.home.mkdir(parents=True)
    sandbox.systmp.mkdir()
    (sandbox.home / "notes.txt").write_text("the user's own notes\n")
    try:
        return _run_in(case, sandbox, monkeypatch)
    finally:
        for undo in reversed(sandbox.extra.get("cleanups", [])):
            undo()


def _run_in(case: Case, sandbox: Sandbox, monkeypatch) -> Outcome:
    from aotv_cosim.fmu import source_check

    if case.setup is not None:
        case.setup(sandbox)
    monkeypatch.chdir(sandbox.home)
    monkeypatch.setenv("TMPDIR", str(sandbox.systmp))
    monkeypatch.setattr(tempfile, "tempdir", str(sandbox.systmp))
    if case.import_limit is not None:
        monkeypatch.setattr(source_check, "IMPORT_TIME_LIMIT", case.import_limit)
        monkeypatch.setattr(source_check, "GRACE", 1.0)
    before, pids = snapshot(sandbox.root), children()
    runner = {"cli": lambda: run_cli(case.what, sandbox), "api": lambda: run_api(case.what, sandbox),
              "process": lambda: run_process(case, sandbox)}[case.face]
    outcome = runner()
    judge(case, outcome, sandbox)
    check_sandbox(case, before, snapshot(sandbox.root), sandbox)
    if case.then is not None:
        case.then(sandbox)
    deadline = time.monotonic() + 3.0
    while children() - pids and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not children() - pids, f"processes left: {children() - pids}"
    return outcome
