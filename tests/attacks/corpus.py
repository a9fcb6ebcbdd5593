"""The attack corpus of issue 34: what a careless or hostile GNC engineer can type or write, at
every user-facing surface, from the command line and from Python (`tests/attacks/harness.py` says
how a case runs and what must hold after it; `test_attack_corpus.py` runs them all).

The cases are derived from what a user types (options, --set, --grid, paths, signals) and writes
(scenario, wiring and dispersion files, guidance laws), not from the package's checks. A case whose
`fixed` is set failed before its fix (the text says how); the others held already. The table in
docs/reliability.md ("Attack corpus") is `table()` of these cases.
"""

import contextlib
import json
import math
import os
import signal
import textwrap
import time
from pathlib import Path

from tests.attacks.harness import ROOT, Case

SCENARIOS = ROOT / "scenarios"


# ---- files a case writes in the user's folder -------------------------------------------------
def law_source(cls="Law", unit="m/s2", start="0.5", extra="", init="", body="return True", before="",
               after="") -> str:
    """A guidance law on aotv_cosim.laws.AotvSlave (the tutorial's form) with the given pieces: the
    parameter `gain` (start, unit, extra keywords), code in __init__, do_step's body, code before
    and after the class."""
    return before + textwrap.dedent(f'''
        from aotv_cosim.laws import AotvSlave


        class {cls}(AotvSlave):
            description = "a law under attack"

            def __init__(self, **kwargs):
                super().__init__(**kwargs)
                self.parameter("gain", {start}, {unit!r}, "gain"{extra})
                self.input("h", 90e3, "m", "altitude")
                self.input("v", 8200.0, "m/s", "speed")
                self.input("gamma", -0.02, "rad", "flight-path angle")
                self.output("u", "m/s2", "lift command", lambda: self.gain, depends_on=("h",))
                {init}

            def do_step(self, current_time, step_size):
                {body}
        ''') + after


def write(path: Path, text) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    return path


def law(name: str, **pieces):
    """setup: home/<name>.py holding `law_source(**pieces)`."""
    return lambda sb: write(sb.home / f"{name}.py", law_source(**pieces))


def flown(name: str, stop=10.0, **pieces):
    """setup: home/<name>.py (a law) and home/w_<name>.json, s_<name>.json: the nominal AOTV wiring
    flying it, a scenario of `stop` s in 0.5 s steps."""
    def setup(sb):
        write(sb.home / f"{name}.py", law_source(**pieces))
        wiring = json.loads((SCENARIOS / "systems" / "aotv_time_linear.json").read_text())
        wiring.pop("$schema")
        wiring["components"]["guidance"] = {"fmu": f"{name}.py"}
        write(sb.home / f"w_{name}.json", json.dumps(wiring))
        write(sb.home / f"s_{name}.json", json.dumps({"system": f"w_{name}.json", "stop": stop, "step": 0.5}))
    return setup


def scenario(name: str, **changes):
    """setup: home/<name>.json, the Monte Carlo scenario montecarlo_robust_density.json with its
    paths made absolute and `changes` applied (a value None removes the key; a callable changes
    the document in place)."""
    def setup(sb):
        doc = json.loads((SCENARIOS / "montecarlo_robust_density.json").read_text())
        doc.pop("$schema")
        doc["system"] = str(SCENARIOS / "systems" / "aotv_robust.json")
        for key, value in changes.items():
            if callable(value):
                value(doc)
            elif value is None:
                doc.pop(key, None)
            else:
                doc[key] = value
        write(sb.home / f"{name}.json", json.dumps(doc))
    return setup


def text_file(name: str, content):
    """setup: home/<name> holding `content` (text or bytes)."""
    return lambda sb: write(sb.home / name, content)


def small_set(sb, folder="set"):
    """home/<folder>: a benchmark set of two laws of benchmark_seed000 (time_linear, robust), their
    paths made absolute, and the user's NOTES.txt."""
    for law_name in ("time_linear", "robust"):
        doc = json.loads((SCENARIOS / "benchmark_seed000" / f"{law_name}.json").read_text())
        doc.pop("$schema")
        doc["system"] = str((SCENARIOS / "benchmark_seed000" / doc["system"]).resolve())
        doc["dispersion_set"] = str((SCENARIOS / "benchmark_seed000" / doc["dispersion_set"]).resolve())
        write(sb.home / folder / f"{law_name}.json", json.dumps(doc))
    write(sb.home / folder / "NOTES.txt", "my notes about the set\n")


def law_wiring(sb, name: str) -> Path:
    """home/<name>.json: the seed-000 time-linear wiring as the user's --law file."""
    wiring = json.loads((SCENARIOS / "systems" / "aotv_time_linear.json").read_text())
    wiring.pop("$schema")
    return write(sb.home / f"{name}.json", json.dumps(wiring))


def nominal_copy(sb, name: str) -> Path:
    """home/<name>: the nominal scenario with its wiring path made absolute."""
    text = (SCENARIOS / "aotv_time_linear_nominal.json").read_text().replace('"systems/', f'"{SCENARIOS}/systems/')
    return write(sb.home / name, text)


def both(*setups):
    def setup(sb):
        for s in setups:
            s(sb)
    return setup


def fifo(name):
    return lambda sb: os.mkfifo(sb.home / name)


def symlink(name, target):
    return lambda sb: os.symlink(target, sb.home / name)


def folder(name):
    return lambda sb: (sb.home / name).mkdir(parents=True)


def run_first(*args):
    """setup: the command line `args` run once before the case (its outputs are the package's)."""
    def setup(sb):
        from tests.attacks.harness import run_cli

        os.chdir(sb.home)
        done = run_cli(args, sb)
        assert done.status == 0, done.stderr
    return setup


def marker_law(name: str, where: str):
    """setup: a law that writes home/marker (its pid) and then sleeps 60 s: at import (`where`
    "import": the source check's child at build), in __init__ of an FMU instance (not the build's
    check: "instantiate") or in do_step after t = 2 s ("step"); with its wiring and scenario."""
    def setup(sb):
        mark = f"open({str(sb.home / 'marker')!r}, 'w').write(str(__import__('os').getpid()))"
        pieces = {"import": {"before": f"import time\n{mark}\ntime.sleep(60)\n"},
                  "instantiate": {"init": f"if str(kwargs.get('resources', '')).endswith('resources'): {mark}; "
                                          "__import__('time').sleep(60)"},
                  "step": {"body": f"if current_time > 2: {mark}; __import__('time').sleep(60)\n"
                                   "                return True"}}[where]
        flown(name, **pieces)(sb)
    return setup


def marked(sb) -> bool:
    return (sb.home / "marker").exists()


def rows_written(sb, folder="out") -> bool:
    rows = sb.home / folder / "rows.csv"
    return rows.exists() and rows.read_text().count("\n") >= 3


def later(seconds: float):
    """A signal condition: true `seconds` after it is first asked (two signals sent at once would be
    one: a process-directed signal does not queue)."""
    start = []

    def ready(sb):
        start.append(start[0] if start else time.monotonic())
        return time.monotonic() - start[0] >= seconds
    return ready


def pid_gone(sb):
    """After a case with a marker law: the process that wrote the marker is gone."""
    pid = int((sb.home / "marker").read_text())
    assert not Path(f"/proc/{pid}").exists() or Path(f"/proc/{pid}/stat").read_text().split()[2] == "Z", pid


def api(function):
    return function


# ---- the cases ----------------------------------------------------------------------------------
OPTIONS_CLI = "option values (command line)"
OPTIONS_API = "option values (Python API)"
SETS = "--set and --grid"
PATHS = "output folders and paths"
FILES = "scenario, wiring and dispersion files"
SOURCES = "user law sources (build)"
CONTRACT = "the law contract (run)"
SIGNALS = "signals"
RESOURCES = "resource limits"
DASK = "Dask schedulers"
FMI3 = "FMI 3.0 surfaces"
REPEATED = "repeated calls and threads"

CASES = []


def case(name, category, face, what, expect, *fragments, **options):
    CASES.append(Case(name, category, face, what, expect, tuple(fragments), **options))


# option values, command line: refused before anything is loaded, built, run or written
for name, args, fragments in [
    ("run-step-0", ["run", "{N}", "--step", "0"], ["--step", "the step 0.0 s is not a finite number above 0"]),
    ("run-step-negative", ["run", "{N}", "--step", "-1"], ["--step", "-1.0"]),
    ("run-step-nan", ["run", "{N}", "--step", "nan"], ["--step", "nan"]),
    ("run-step-inf", ["run", "{N}", "--step", "inf"], ["--step", "inf"]),
    ("run-start-nan", ["run", "{N}", "--start", "nan"], ["--start", "the start nan s"]),
    ("run-stop-minus-inf", ["run", "{N}", "--stop", "-1e400"], ["--stop", "-inf"]),
    ("run-step-timeout-0", ["run", "{N}", "--step-timeout", "0"], ["--step-timeout", "the time limit 0.0 s"]),
    ("run-step-timeout-negative", ["run", "{N}", "--step-timeout", "-5"], ["--step-timeout"]),
    ("run-step-timeout-nan", ["run", "{N}", "--step-timeout", "nan"], ["--step-timeout", "nan"]),
    ("run-fmi-calls-upper", ["run", "{N}", "--fmi-calls", "C"], ["--fmi-calls", "unknown value 'C'"]),
    ("run-format-unknown", ["run", "{N}", "--format", "xml"], ["--format", "xml"]),
    ("run-scenario-missing", ["run", "nope.json"], ["nope.json"]),
    ("run-scenario-folder", ["run", "{home}"], ["{home}"]),
    ("mc-runs-0", ["montecarlo", "{MC}", "--runs", "0"], ["--runs", "runs 0 is outside 1..1000000"]),
    ("mc-runs-negative", ["montecarlo", "{MC}", "--runs", "-3"], ["--runs", "runs -3 is outside"]),
    ("mc-runs-too-many", ["montecarlo", "{MC}", "--runs", "1000001"], ["--runs", "1000001"]),
    ("mc-runs-text", ["montecarlo", "{MC}", "--runs", "abc"], ["--runs", "abc"]),
    ("mc-runs-float-text", ["montecarlo", "{MC}", "--runs", "1e3"], ["--runs", "1e3"]),
    ("mc-workers-0", ["montecarlo", "{MC}", "--runs", "2", "--workers", "0"], ["--workers", "workers 0 is outside"]),
    ("mc-workers-huge", ["montecarlo", "{MC}", "--runs", "2", "--workers", "100000"], ["--workers", "100000"]),
    ("mc-seed-negative", ["montecarlo", "{MC}", "--runs", "2", "--seed", "-1"], ["--seed", "seed -1 is outside"]),
    ("mc-seed-2-64", ["montecarlo", "{MC}", "--runs", "2", "--seed", str(2**64)], ["--seed", str(2**64)]),
    ("mc-max-rss-0", ["montecarlo", "{MC}", "--runs", "2", "--max-rss", "0"],
     ["--max-rss", "the memory limit 0.0 MiB"]),
    ("mc-max-rss-nan", ["montecarlo", "{MC}", "--runs", "2", "--max-rss", "nan"], ["--max-rss", "nan"]),
    ("mc-max-rss-negative", ["montecarlo", "{MC}", "--runs", "2", "--max-rss", "-1"], ["--max-rss"]),
    ("mc-step-timeout-inf", ["montecarlo", "{MC}", "--runs", "2", "--step-timeout", "inf"], ["--step-timeout"]),
    ("bench-runs-0", ["benchmark", "{SET}", "--runs", "0"], ["--runs", "runs 0"]),
    ("bench-law-missing", ["benchmark", "{SET}", "--law", "missing.json"], ["missing.json", "--law"]),
    ("bench-law-folder", ["benchmark", "{SET}", "--law", "{home}"], ["--law"]),
    ("bench-law-device", ["benchmark", "{SET}", "--law", "/dev/null"], ["/dev/null", "--law"]),
    ("bench-workers-0", ["benchmark", "{SET}", "--workers", "0"], ["--workers"]),
    ("bench-set-unknown", ["benchmark", "benchmark_nope"], ["benchmark_nope", "benchmark_seed000"]),
    ("sweep-grid-no-equals", ["sweep", "{P}", "--grid", "vehicle.gamma0"], ["--grid", "cannot read the grid"]),
    ("sweep-grid-two-fields", ["sweep", "{P}", "--grid", "vehicle.gamma0=1:2"], ["--grid"]),
    ("sweep-grid-0-points", ["sweep", "{P}", "--grid", "vehicle.gamma0=-0.03:-0.01:0"], ["asks for 0 points"]),
    ("sweep-grid-1e9-points", ["sweep", "{P}", "--grid", "vehicle.gamma0=-0.03:-0.01:1000000000"],
     ["asks for 1000000000 points"]),
    ("sweep-grid-nan", ["sweep", "{P}", "--grid", "vehicle.gamma0=nan,-0.02"], ["not finite"]),
    ("sweep-grid-twice", ["sweep", "{P}", "--grid", "vehicle.gamma0=-0.02", "--grid", "vehicle.gamma0=-0.03"],
     ["given by several grids"]),
    ("sweep-grids-too-many-points", ["sweep", "{P}", "--grid", "vehicle.gamma0=-0.03:-0.01:1000",
                                     "--grid", "vehicle.v0=8000:8300:1000"], ["the grids make 1000000 points"]),
    ("corridor-l2d-0", ["corridor", "{P}", "--lift-to-drag", "0"], ["--lift-to-drag", "L/D 0.0"]),
    ("corridor-l2d-nan", ["corridor", "{P}", "--lift-to-drag", "nan"], ["--lift-to-drag"]),
    ("corridor-tolerance-inf", ["corridor", "{P}", "--lift-to-drag", "1", "--tolerance", "inf"], ["--tolerance"]),
    ("corridor-bracket-past-vertical", ["corridor", "{P}", "--lift-to-drag", "1", "--bracket", "-3", "-0.002"],
     ["--bracket", "(-3.0, -0.002)"]),
    ("corridor-bracket-reversed", ["corridor", "{P}", "--lift-to-drag", "1", "--bracket", "-0.002", "-0.08"],
     ["--bracket"]),
    ("corridor-bracket-nan", ["corridor", "{P}", "--lift-to-drag", "1", "--bracket", "nan", "-0.01"], ["--bracket"]),
    ("build-fmi-4", ["build-fmus", "LiftActuator", "--fmi", "4"], ["--fmi"]),
    ("export-fmi-1", ["export-ssp", "{N}", "-o", "x.ssp", "--fmi", "1"], ["--fmi"]),
    ("export-step-0", ["export-ssp", "{N}", "-o", "x.ssp", "--step", "0"], ["--step"]),
    ("describe-empty", ["describe", ""], ["FMU|WIRING"]),
    ("describe-missing-fmu", ["describe", "nope.fmu"], ["nope.fmu"]),
    ("validate-nothing", ["validate"], ["FILES"]),
]:
    case(name, OPTIONS_CLI, "cli", args, "bad", *fragments)

case("run-step-timeout-tiny", OPTIONS_CLI, "cli", ["run", "{N}", "--step-timeout", "1e-9"], "bad",
     "--step-timeout", "at least 0.1",
     fixed="flown with no step limit at all (the watchdog never saw a step that long)")
case("mc-step-timeout-tiny", OPTIONS_CLI, "cli", ["montecarlo", "{MC}", "--runs", "2", "--step-timeout", "1e-9"],
     "bad", "--step-timeout", fixed="flown with no step limit")
case("mc-max-rss-tiny", OPTIONS_CLI, "cli", ["montecarlo", "{MC}", "--runs", "2", "--max-rss", "1e-9"], "bad",
     "--max-rss", "at least 64", fixed="flown with no memory limit (1e-9 MiB rounded to 0 bytes: no limit)")
case("mc-max-rss-gib-for-mib", OPTIONS_CLI, "cli", ["montecarlo", "{MC}", "--runs", "2", "--max-rss", "2"], "bad",
     "--max-rss", "the memory limit 2.0 MiB", fixed="every run flown and killed at start (2 MiB meant 2 GiB)")
case("build-unknown-name", OPTIONS_CLI, "cli", ["build-fmus", "PointMassVehicel"], "bad",
     "PointMassVehicel", "did you mean PointMassVehicle", fixed="exit 1 (a BuildError), no close names")

# option values from Python: InputError with the command line's line, before anything is done
N, MC, P = "{N}", "{MC}", "{P}"


def _p(sb, text):
    return sb.path(text)


def api_case(name, call, *fragments, **options):
    case(name, OPTIONS_API, "api", call, options.pop("expect", "bad"), *fragments, **options)


def _aotv():
    import aotv_cosim

    return aotv_cosim


api_case("run-none", lambda sb: _aotv().run(None), "SCENARIO", "got None")
api_case("run-bytes", lambda sb: _aotv().run(_p(sb, N).encode()), "(bytes)")
api_case("run-int", lambda sb: _aotv().run(5), "got 5 (int)")
api_case("run-empty-path", lambda sb: _aotv().run(""), "not a usable path")
api_case("run-set-text", lambda sb: _aotv().run(_p(sb, N), set="vehicle.h0=1"), "--set", "expected a mapping")
api_case("run-set-key-int", lambda sb: _aotv().run(_p(sb, N), set={1: 2}), "cannot read the name 1")
api_case("run-set-nan", lambda sb: _aotv().run(_p(sb, N), set={"vehicle.h0": math.nan}), "vehicle.h0", "nan")
api_case("run-set-dict-value", lambda sb: _aotv().run(_p(sb, N), set={"vehicle.h0": {"a": 1}}), "vehicle.h0")
api_case("run-set-int-beyond-float", lambda sb: _aotv().run(_p(sb, N), set={"vehicle.h0": 10**400}), "vehicle.h0",
         fixed="OverflowError from deep inside, not InputError")
api_case("run-stop-int-beyond-float", lambda sb: _aotv().run(_p(sb, N), stop=10**400), "--stop",
         fixed="OverflowError")
api_case("run-stop-text", lambda sb: _aotv().run(_p(sb, N), stop="100"), "--stop", "got '100' (str)")
api_case("run-plots-without-out", lambda sb: _aotv().run(_p(sb, N), plots=True), "plots", "give out=FOLDER")
api_case("run-formats-unknown", lambda sb: _aotv().run(_p(sb, N), formats="xml"), "--format", "'xml'")
api_case("run-formats-empty", lambda sb: _aotv().run(_p(sb, N), formats=[]), "--format", "(none given)")
api_case("run-step-timeout-bool", lambda sb: _aotv().run(_p(sb, N), step_timeout=True), "--step-timeout", "(bool)")
api_case("run-fmi-calls-upper", lambda sb: _aotv().run(_p(sb, N), fmi_calls="C"), "--fmi-calls")
api_case("mc-runs-0", lambda sb: _aotv().montecarlo(_p(sb, MC), 0), "--runs", "runs 0 is outside")
api_case("mc-runs-text", lambda sb: _aotv().montecarlo(_p(sb, MC), "2"), "--runs", "got '2' (str)")
api_case("mc-runs-float", lambda sb: _aotv().montecarlo(_p(sb, MC), 2.0), "--runs", "got 2.0 (float)")
api_case("mc-runs-bool", lambda sb: _aotv().montecarlo(_p(sb, MC), True), "--runs", "got True (bool)")
api_case("mc-workers-0", lambda sb: _aotv().montecarlo(_p(sb, MC), 2, workers=0), "--workers")
api_case("mc-workers-float", lambda sb: _aotv().montecarlo(_p(sb, MC), 2, workers=2.5), "--workers", "(float)")
api_case("mc-seed-negative", lambda sb: _aotv().montecarlo(_p(sb, MC), 2, seed=-1), "--seed")
api_case("mc-keep-series-1", lambda sb: _aotv().montecarlo(_p(sb, MC), 2, keep_series=1), "--keep-series")
api_case("mc-resume-without-out", lambda sb: _aotv().montecarlo(_p(sb, MC), 2, resume=True), "--resume",
         "give out=FOLDER")
api_case("mc-scheduler-int", lambda sb: _aotv().montecarlo(_p(sb, MC), 2, scheduler=8786), "--scheduler")
api_case("mc-scheduler-object", lambda sb: _aotv().montecarlo(_p(sb, MC), 2, scheduler=object()), "--scheduler")
api_case("mc-max-rss-0", lambda sb: _aotv().montecarlo(_p(sb, MC), 2, max_rss=0), "--max-rss")
api_case("mc-step-timeout-inf", lambda sb: _aotv().montecarlo(_p(sb, MC), 2, step_timeout=math.inf),
         "--step-timeout")
api_case("bench-runs-0", lambda sb: _aotv().benchmark(_p(sb, "{SET}"), runs=0), "--runs")
api_case("bench-law-none", lambda sb: _aotv().benchmark(_p(sb, "{SET}"), [None], runs=1), "--law", "got None")
api_case("bench-laws-dict", lambda sb: _aotv().benchmark(_p(sb, "{SET}"), {"a": 1}, runs=1), "--law")
api_case("bench-set-none", lambda sb: _aotv().benchmark(None, runs=1), "SET", "got None")
api_case("bench-reuse-0", lambda sb: _aotv().benchmark(_p(sb, "{SET}"), runs=1, reuse=0), "--refly")
api_case("sweep-grids-none", lambda sb: _aotv().sweep(_p(sb, P), None), "--grid")
api_case("sweep-grids-empty", lambda sb: _aotv().sweep(_p(sb, P), {}), "--grid", "no grid given")
api_case("sweep-grid-text-values", lambda sb: _aotv().sweep(_p(sb, P), {"vehicle.gamma0": "-0.02"}), "--grid")
api_case("sweep-grid-nan", lambda sb: _aotv().sweep(_p(sb, P), {"vehicle.gamma0": [math.nan]}), "--grid", "nan")
api_case("sweep-grid-no-value", lambda sb: _aotv().sweep(_p(sb, P), {"vehicle.gamma0": []}), "has no value")
api_case("sweep-grid-too-long", lambda sb: _aotv().sweep(_p(sb, P), {"vehicle.gamma0": range(100001)}),
         "has 100001 values")
api_case("sweep-grid-name-int", lambda sb: _aotv().sweep(_p(sb, P), {1: [1.0]}), "cannot read the grid name")
api_case("corridor-l2d-0", lambda sb: _aotv().corridor(_p(sb, P), lift_to_drag=0), "--lift-to-drag")
api_case("corridor-l2d-text", lambda sb: _aotv().corridor(_p(sb, P), lift_to_drag="5"), "--lift-to-drag")
api_case("corridor-bracket-three", lambda sb: _aotv().corridor(_p(sb, P), lift_to_drag=1,
                                                              bracket=(-0.1, -0.05, -0.01)), "--bracket")
api_case("corridor-bracket-mapping", lambda sb: _aotv().corridor(_p(sb, P), lift_to_drag=1,
                                                                bracket={-0.1: 1, -0.01: 2}), "--bracket",
         fixed="its keys taken as the bracket and the corridor flown")
api_case("corridor-tolerance-negative", lambda sb: _aotv().corridor(_p(sb, P), lift_to_drag=1, tolerance=-1),
         "--tolerance")
api_case("describe-none", lambda sb: _aotv().describe(None), "FMU|WIRING", "got None")
api_case("build-none-in-list", lambda sb: _aotv().build_fmus([None]), "NAME|SOURCE.py", "got None")
api_case("build-unknown", lambda sb: _aotv().build_fmus("Nope"), "no FMU named 'Nope'",
         fixed="BuildError (exit 1): a misspelt name was taken for this package's failure")
api_case("build-fmi-4", lambda sb: _aotv().build_fmus("LiftActuator", fmi_version=4), "--fmi")
api_case("build-fmi-text", lambda sb: _aotv().build_fmus("LiftActuator", fmi_version="3"), "--fmi")
api_case("validate-nothing", lambda sb: _aotv().validate([]), "FILES", "no file given")
api_case("export-out-none", lambda sb: _aotv().export_ssp(_p(sb, N), None), "--out", "got None")
api_case("export-fmi-4", lambda sb: _aotv().export_ssp(_p(sb, N), "x.ssp", fmi_version=4), "--fmi")
api_case("execute-not-options", lambda sb: __import__("aotv_cosim.api").api.execute("run"), "options",
         "not an options object")


def _np():
    import numpy

    return numpy


api_case("mc-runs-numpy-int", lambda sb: _aotv().montecarlo(_p(sb, MC), _np().int64(2), workers=1, stop=20),
         expect="ok", fmus=True, fixed="refused: 'runs must be an integer, got np.int64(2)'")
api_case("run-stop-numpy-float32", lambda sb: _aotv().run(_p(sb, N), stop=_np().float32(1.0)), expect="ok",
         fmus=True, fixed="refused: 'the stop must be a number, got np.float32(1.0)'")
api_case("run-set-numpy-int", lambda sb: _aotv().run(_p(sb, N), set={"vehicle.gravity_model": _np().int64(0)},
                                                     stop=1.0), expect="ok", fmus=True,
         fixed="refused as 'not a finite number, a Boolean or a text'")
api_case("sweep-grid-numpy-float32", lambda sb: _aotv().sweep(_p(sb, P), {"vehicle.gamma0": _np().array(
    [-0.02], dtype="float32")}, workers=1), expect="ok", fmus=True, fixed="refused: 'value must be a number'")

# --set and --grid, from what a user types
for name, value, fragments, fmus in [
    ("set-no-equals", "vehicle.h0", ["--set", "no component.variable before an '='"], False),
    ("set-no-name", "=1", ["--set"], False),
    ("set-no-variable", "vehicle.=1", ["--set", "cannot read the name 'vehicle.'"], False),
    ("set-null", "vehicle.h0=null", ["--set", "None"], False),
    ("set-list", "vehicle.h0=[1,2]", ["--set", "[1, 2]"], False),
    ("set-object", 'vehicle.h0={"a":1}', ["--set"], False),
    ("set-unicode-name", "véhicule.h0=1", ["--set"], False),
    ("set-newline-name", "vehi\ncle.h0=1", ["--set"], False),
    ("set-degrees-for-rad", "vehicle.gamma0=-65.7", ["gamma0 = -65.7 is outside its physical range"], True),
    ("set-connected-input", "vehicle.rho=1", ["input rho is both connected and given a value"], True),
    ("set-unknown-variable", "vehicle.h00=1", ["did you mean h0?"], True),
    ("set-unknown-component", "engine.thrust=1", ["unknown component 'engine'"], True),
    ("set-output", "vehicle.h=1", ["h is an output"], True),
    ("set-float-for-integer", "vehicle.gravity_model=0.5", ["gravity_model is Integer, got 0.5"], True),
    ("set-integer-out-of-range", "vehicle.gravity_model=7", ["outside its physical range [0, 1]"], True),
    ("set-text-for-real", "vehicle.h0=high", ["h0 is Real, got 'high'"], True),
    ("set-boolean-for-real", "vehicle.h0=true", ["h0 is Real, got True"], True),
    ("set-1e400", "vehicle.h0=1e400", ["h0 is Real, got '1e400'"], True),
]:
    case(name, SETS, "cli", ["run", "{N}", "--out", "{out}", "--set", value], "bad", *fragments, fmus=fmus)
case("set-nested-past-the-parser", SETS, "cli", ["run", "{N}", "--out", "{out}", "--set", "vehicle.h0=" + "[" * 50000],
     "bad", "h0 is Real, got '[[[", fmus=True, fixed="exit 3, RecursionError")
case("set-given-twice", SETS, "cli", ["run", "{N}", "--out", "{out}", "--set", "vehicle.h0=91000", "--set",
                                      "vehicle.h0=89000"], "bad", "vehicle.h0 is given twice",
     fixed="the last value silently won")
case("set-typed-enumeration-name", SETS, "cli", ["run", "{home}/typed.json", "--out", "{out}", "--set",
                                                 "t.mode=Sideways"],
     "bad", "mode is an Enumeration, got 'Sideways'", fmus=True,
     setup=lambda sb: (write(sb.home / "typed_w.json", json.dumps({"components": {"t": {
         "fmu": str(sb.names["TYPED"]), "parameters": {"u": 0.0, "m": 0}}}, "connections": []})),
                       write(sb.home / "typed.json", json.dumps({"system": "typed_w.json", "stop": 1.0, "step": 0.5}))))
for name, grid, fragments in [
    ("grid-connected-input", "vehicle.rho=0.1,0.2", ["input rho is both connected and given a value"]),
    ("grid-out-of-range", "vehicle.gamma0=-3,-0.02", ["gamma0 = -3.0 is outside its physical range"]),
    ("grid-integer", "vehicle.gravity_model=0,1", ["is not a Real parameter of the system"]),
    ("grid-output", "vehicle.h=1,2", ["is not a Real parameter of the system"]),
    ("grid-unknown-component", "engine.thrust=1,2", ["is not a Real parameter of the system"]),
]:
    case(name, SETS, "cli", ["sweep", "{P}", "--out", "{out}", "--grid", grid], "bad", *fragments, fmus=True)
case("grid-and-set-one-parameter", SETS, "cli", ["sweep", "{P}", "--out", "{out}", "--grid", "vehicle.gamma0=-0.02",
                                                 "--set", "vehicle.gamma0=-0.03"], "bad",
     "vehicle.gamma0 is given both by --set and by --grid", fixed="the grid's value silently won over the --set")

# output folders and paths: what the command may write, overwrite, delete or read back
for name, setup, out in [("devnull", None, "/dev/null"), ("fifo", fifo("pipe"), "{home}/pipe"),
                         ("a-file", text_file("afile", "mine\n"), "{home}/afile"),
                         ("under-a-file", text_file("afile", "mine\n"), "{home}/afile/sub"),
                         ("symlink-loop", both(symlink("loop1", "loop2"), symlink("loop2", "loop1")), "{home}/loop1"),
                         ("dangling-symlink", symlink("dangling", "/nonexistent/folder"), "{home}/dangling")]:
    case(f"run-out-{name}", PATHS, "cli", ["run", "{N}", "--out", out, "--stop", "1"], "bad", "--out", setup=setup)
    case(f"build-out-{name}", PATHS, "cli", ["build-fmus", "LiftActuator", "--out", out], "bad", "--out", setup=setup,
         fixed="" if name in ("a-file", "dangling-symlink") else "exit 3 (FileExistsError, NotADirectoryError)")
for command, args in [("mc", ["montecarlo", "{MC}", "--runs", "1"]),
                      ("sweep", ["sweep", "{P}", "--grid", "vehicle.gamma0=-0.02"]),
                      ("corridor", ["corridor", "{P}", "--lift-to-drag", "1"]),
                      ("check", ["check", "{N}"]), ("bench", ["benchmark", "{SET}", "--runs", "1"])]:
    case(f"{command}-out-devnull", PATHS, "cli", [*args, "--out", "/dev/null"], "bad", "/dev/null", fmus=True)
case("build-out-users-fmu", PATHS, "cli", ["build-fmus", "LiftActuator", "--out", "{home}/fmus"], "bad",
     "LiftActuator.fmu is there and was not written by aotv-cosim", setup=text_file("fmus/LiftActuator.fmu", "mine"),
     fixed="the user's LiftActuator.fmu overwritten")
case("export-over-the-scenario", PATHS, "cli", ["export-ssp", "{home}/s.json", "-o", "{home}/s.json"], "bad",
     "s.json is there and was not written by aotv-cosim export-ssp", setup=lambda sb: nominal_copy(sb, "s.json"),
     fixed="the scenario replaced by the archive (the user's input destroyed)")
case("export-over-the-wiring", PATHS, "cli", ["export-ssp", "{N}", "-o", "{W}"], "bad", "was not written by aotv-cosim",
     fixed="the shipped wiring replaced by the archive")
case("export-over-a-users-file", PATHS, "cli", ["export-ssp", "{N}", "-o", "{home}/notes.txt"], "bad",
     "notes.txt is there and was not written", fixed="the user's file overwritten")
case("export-over-a-dangling-symlink", PATHS, "cli", ["export-ssp", "{N}", "-o", "{home}/link.ssp"], "bad",
     "link.ssp is there", setup=symlink("link.ssp", "/nonexistent/x.ssp"), fixed="the user's symlink replaced")
case("export-to-devnull", PATHS, "cli", ["export-ssp", "{N}", "-o", "/dev/null"], "bad", "/dev/null")
case("export-to-a-folder", PATHS, "cli", ["export-ssp", "{N}", "-o", "{home}"], "bad", "-o")
case("export-again-over-its-archive", PATHS, "cli", ["export-ssp", "{N}", "-o", "{home}/x.ssp"], "ok", "x.ssp",
     setup=run_first("export-ssp", "{N}", "-o", "{home}/x.ssp"), fmus=True)
case("run-out-users-summary", PATHS, "cli", ["run", "{N}", "--out", "{home}", "--stop", "1"], "bad",
     "summary.json is there and was not written by aotv-cosim", setup=text_file("summary.json", "{}"), fmus=True)
case("run-out-result-name-folder", PATHS, "cli", ["run", "{N}", "--out", "{home}", "--stop", "1"], "bad",
     "timeseries.csv is a folder left in the way", setup=folder("timeseries.csv"), fmus=True)
case("run-out-the-scenario-file", PATHS, "cli", ["run", "{home}/s.json", "--out", "{home}/s.json"], "bad",
     "not a folder: a file is in the way", setup=lambda sb: nominal_copy(sb, "s.json"),
     fmus=True)
case("run-out-home-keeps-notes", PATHS, "cli", ["run", "{N}", "--out", "{home}", "--stop", "1", "--no-plots"], "ok",
     "results in", fmus=True)
for law_file, fragment in [("..json", "'.'"), (".json", "'.json'"), ("laws.json", "'laws'"), ("rows.json", "'rows'"),
                           ("Scorecard.json", "'Scorecard'"), ("report.v2.json", "'report.v2'")]:
    case(f"bench-law-named-{law_file}", PATHS, "cli", ["benchmark", "{SET}", "--runs", "1", "--out", "{out}", "--law",
                                                       f"{{home}}/{law_file}"], "bad",
         f"the law name {fragment}", "would alias the benchmark folder's own files",
         setup=lambda sb, f=law_file: write(sb.home / f, json.dumps({"components": {}})))
case("bench-two-laws-one-name", PATHS, "cli", ["benchmark", "{SET}", "--runs", "1", "--out", "{out}", "--law",
                                               "{home}/a/mine.json", "--law", "{home}/b/mine.json"], "bad",
     "a law named 'mine' is already given by another --law file",
     setup=lambda sb: (law_wiring(sb, "a/mine"), law_wiring(sb, "b/mine")))
case("bench-law-named-as-a-set-law", PATHS, "cli", ["benchmark", "{SET}", "--runs", "1", "--out", "{out}", "--law",
                                                    "{home}/time_linear.json"], "bad",
     "a law named 'time_linear' is already in the set", setup=lambda sb: law_wiring(sb, "time_linear"))
case("bench-out-is-the-set-twice", PATHS, "cli", ["benchmark", "{home}/set", "--runs", "1", "--out", "{home}/set"],
     "ok", "2 laws x 1 runs", fmus=True,
     setup=both(small_set, run_first("benchmark", "{home}/set", "--runs", "1", "--out", "{home}/set")),
     fixed="exit 2 at the second call: its own scorecard.json read as a law of the set")
case("bench-refly-keeps-users-notes", PATHS, "cli", ["benchmark", "{home}/set", "--runs", "1", "--out", "{home}/set",
                                                     "--refly"], "ok", "2 flown now", fmus=True,
     setup=both(small_set, run_first("benchmark", "{home}/set", "--runs", "1", "--out", "{home}/set")))
case("check-folder-holding-a-run", PATHS, "cli", ["check", "{home}/chk", "--out", "{out}"], "ok", "1 passed", fmus=True,
     setup=both(lambda sb: write(sb.home / "chk" / "exit.json", (SCENARIOS / "aotv_time_linear_exit.json").read_text()
                                 .replace('"systems/', f'"{SCENARIOS}/systems/')),
                run_first("run", "{home}/chk/exit.json", "--out", "{home}/chk", "--no-plots")),
     fixed="exit 2: the run's summary.json read as a scenario of the folder")
case("mc-refused-scheduler-leaves-no-folder", PATHS, "cli", ["montecarlo", "{MC}", "--runs", "1", "--out", "{out}",
                                                             "--scheduler", "inproc://x"], "bad",
     "cannot connect to the Dask scheduler", fmus=True,
     fixed="exit 3 (ValueError), a campaign folder with campaign.json and an empty rows.csv left")
case("bench-refused-law-leaves-the-users-folder-clean", PATHS, "cli",
     ["benchmark", "{SET}", "--runs", "1", "--out", "{home}", "--law", "{home}/laws.json"], "bad", "'laws'",
     setup=text_file("laws.json", json.dumps({"components": {}})),
     fixed="a .lock and a .aotv-written left in the user's folder by the refused command")
case("figures-seed002-of-a-folder-that-is-no-run", PATHS, "cli", ["figures", "seed002", "{home}"], "bad",
     "{home}/timeseries.csv", "cannot read the run's time series",
     fixed="exit 3 (FileNotFoundError); its claim would have left a lock in the folder")
case("figures-seed002-of-another-scenario", PATHS, "cli", ["figures", "seed002", "{home}/run"], "bad",
     "the run recorded no vehicle.mach", fmus=True,
     setup=run_first("run", "{N}", "--out", "{home}/run", "--stop", "1", "--no-plots"),
     fixed="exit 3 (KeyError: 'vehicle.mach')")
for figures_of in ("seed000", "seed001", "seed003"):
    case(f"figures-{figures_of}-out-devnull", PATHS, "cli", ["figures", figures_of, "--out", "/dev/null"], "bad",
         "/dev/null: --out", fixed="exit 3 (FileExistsError)")
for name, setup, target in [("device", None, "/dev/zero"), ("fifo", fifo("pipe.json"), "{home}/pipe.json"),
                            ("folder", None, "{home}")]:
    case(f"describe-a-{name}", PATHS, "cli", ["describe", target], "bad", "is " if name != "folder" else "is a folder",
         setup=setup, fixed="'file not found' (it was there)")
case("resume-corrupt-campaign", PATHS, "cli", ["montecarlo", "{MC}", "--runs", "2", "--out", "{out}", "--resume"],
     "bad", "corrupt campaign file", setup=text_file("out/campaign.json", "{not json"))
case("resume-corrupt-rows", PATHS, "cli", ["montecarlo", "{MC}", "--runs", "2", "--out", "{out}", "--resume"], "bad",
     "not a number", setup=text_file("out/rows.csv", "run,status\nabc,completed\n"))

# scenario, wiring and dispersion files
for name, content, fragments in [
    ("deep-array", "[" * 200000 + "]" * 200000, ["nested too deeply"]),
    ("deep-object", '{"a":' * 100000 + "1" + "}" * 100000, ["nested too deeply"]),
    ("utf16", json.dumps({"system": "w.json", "stop": 1}).encode("utf-16"), ["not UTF-8"]),
    ("unicode-component", json.dumps({"system": "w.json", "stop": 1, "parameters": {"véhicule.h0": 1}}),
     ["does not match"]),
    ("trailing-space-name", json.dumps({"system": "w.json", "stop": 1, "parameters": {"vehicle.h0 ": 1}}),
     ["does not match"]),
    ("nan-literal", '{"system": "w.json", "stop": NaN}', ["NaN is not a finite number"]),
    ("duplicate-key", '{"system": "w.json", "stop": 1, "stop": 2}', ["duplicate key 'stop'"]),
    ("system-is-itself", json.dumps({"system": "s.json", "stop": 1}), ["Additional properties"]),
]:
    case(f"file-{name}", FILES, "cli", ["validate", "{home}/s.json"], "bad", *fragments,
         setup=text_file("s.json", content))
case("file-byte-order-mark", FILES, "cli", ["validate", "{home}/s.json"], "ok", "ok:", fmus=True,
     setup=text_file("s.json", b"\xef\xbb\xbf" + json.dumps({"system": str(SCENARIOS / "systems" / "aotv_robust.json"),
                                                             "stop": 10}).encode()),
     fixed="'Unexpected UTF-8 BOM; correct the JSON syntax there' (a BOM an editor wrote, invisible)")
case("file-lone-surrogate-description", FILES, "cli", ["run", "{home}/s.json", "--out", "{out}", "--no-plots"], "ok",
     setup=scenario("s", description="\ud800", dispersions=None, montecarlo=None, stop=10.0), fmus=True)
for name, dispersions, fragments in [
    ("low-equals-high", {"atmosphere.density_factor": {"distribution": "uniform", "low": 1.0, "high": 1.0}},
     ["low (1.0) must be below high (1.0)"]),
    ("low-above-high", {"atmosphere.density_factor": {"distribution": "uniform", "low": 1.2, "high": 0.8}},
     ["must be below high"]),
    ("truncated-reversed", {"atmosphere.density_factor": {"distribution": "truncated_normal", "mean": 1.0, "std": 0.1,
                                                          "low": 1.2, "high": 0.8}}, ["must be below high"]),
    ("connected-input", {"vehicle.rho": {"distribution": "uniform", "low": 0.1, "high": 0.2}},
     ["vehicle.rho is not a Real parameter"]),
    ("output", {"vehicle.h": {"distribution": "uniform", "low": 0.1, "high": 0.2}},
     ["vehicle.h is not a Real parameter"]),
    ("integer", {"vehicle.gravity_model": {"distribution": "uniform", "low": 0, "high": 1}},
     ["is not a Real parameter"]),
    ("unknown", {"vehicle.nope": {"distribution": "uniform", "low": 0, "high": 1}}, ["vehicle.nope"]),
    ("negative-std", {"vehicle.h0": {"distribution": "normal", "mean": 9e4, "std": -1}}, ["dispersions"]),
    ("degrees-for-rad", {"vehicle.gamma0": {"distribution": "uniform", "low": -2.0, "high": -1.0}},
     ["lies outside its physical range"]),
]:
    case(f"dispersion-{name}", FILES, "cli", ["montecarlo", "{home}/s.json", "--runs", "2", "--out", "{out}"], "bad",
         *fragments, setup=scenario("s", dispersions=dispersions), fmus=True)
case("dispersion-none", FILES, "cli", ["montecarlo", "{home}/s.json", "--runs", "2", "--out", "{out}"], "bad",
     "declares no dispersions", setup=scenario("s", dispersions={}), fmus=True)
case("dispersion-near-the-float-range", FILES, "cli", ["montecarlo", "{home}/s.json", "--runs", "2", "--out", "{out}"],
     "ok", setup=scenario("s", dispersions={"vehicle.h0": {"distribution": "uniform", "low": 1e300, "high": 1.7e308}},
                          montecarlo=None), fmus=True,
     fixed="every run flown, then exit 3 writing summary.json (its mean overflowed to inf) and summary.json.part left")
case("dispersion-normal-huge-std", FILES, "cli", ["montecarlo", "{home}/s.json", "--runs", "2", "--out", "{out}"],
     "ok", setup=scenario("s", dispersions={"vehicle.h0": {"distribution": "normal", "mean": 9e4, "std": 1e300}},
                          montecarlo=None), fmus=True, fixed="exit 3 and summary.json.part left")
for name, value, fragments in [("self", "s.json", ["Additional properties"]), ("dev-zero", "/dev/zero", ["/dev/zero"]),
                               ("folder", ".", ["is a folder"]), ("missing", "none.json", ["file not found"])]:
    case(f"dispersion-set-{name}", FILES, "cli", ["validate", "{home}/s.json"], "bad", "dispersion_set", *fragments,
         setup=scenario("s", dispersion_set=value), fmus=True)
for name, change, fragments in [
    ("band-0", lambda d: d["montecarlo"]["outcome"].update(band=0), ["band: 0 is less than or equal to the minimum"]),
    ("target-negative", lambda d: d["montecarlo"]["outcome"].update(target_apogee=-1), ["target_apogee"]),
    ("unknown-key", lambda d: d["montecarlo"]["outcome"].update(bnad=5), ["'bnad' was unexpected"]),
    ("vehicle-not-a-vehicle", lambda d: d["montecarlo"]["outcome"].update(vehicle="atmosphere"),
     ["atmosphere.h, atmosphere.v, atmosphere.gamma"]),
    ("actuator-unknown", lambda d: d["montecarlo"]["outcome"].update(actuator="nobank"),
     ["'nobank' names no component"]),
    ("scatter-unknown", lambda d: d["montecarlo"].update(scatter=["vehicle.v", "vehicle.nope"]), ["montecarlo"]),
]:
    case(f"outcome-{name}", FILES, "cli", ["validate", "{home}/s.json"], "bad", *fragments,
         setup=scenario("s", montecarlo=change), fmus=True)
for name, fmu, setup, fragments in [
    ("fifo-source", "law.py", fifo("law.py"), ["not a regular file"]),
    ("folder-named-fmu", "x.fmu", folder("x.fmu"), ["x.fmu"]),
    ("missing-source", "../nowhere/law.py", None, ["FMU source file not found"]),
    ("device-source", "zero.py", symlink("zero.py", "/dev/zero"), ["not a regular file"]),
    ("not-a-zip", "fake.fmu", text_file("fake.fmu", "not a zip"), ["fake.fmu"]),
]:
    def wiring_setup(sb, fmu=fmu, setup=setup):
        if setup is not None:
            setup(sb)
        write(sb.home / "w.json", json.dumps({"components": {"g": {"fmu": fmu}}, "connections": []}))
    case(f"wiring-{name}", FILES, "cli", ["validate", "{home}/w.json"], "bad", "components.g.fmu", *fragments,
         setup=wiring_setup)

# user law sources: built into FMUs (imported once, in a child process with a time limit)
for name, pieces, fragments in [
    ("unit-km", {"unit": "km"}, ["unit 'km': 'km' is not an SI unit"]),
    ("unit-superscript", {"unit": "m/s²"}, ["cannot read '²'"]),
    ("unit-empty", {"unit": ""}, ["unit ''"]),
    ("unit-space", {"unit": "m s-2"}, ["cannot read ' s-2'"]),
    ("unit-degrees", {"unit": "deg"}, ["'deg' is not an SI unit"]),
    ("nominal-zero", {"extra": ", nominal=0.0"}, ["nominal 0.0 must be a finite number above 0"]),
    ("nominal-nan", {"extra": ", nominal=float('nan')"}, ["nominal nan"]),
    ("nominal-text", {"extra": ", nominal='1'"}, ["nominal '1'"]),
    ("min-nan", {"extra": ", min=float('nan')"}, ["min and max must be numbers"]),
    ("min-above-max", {"extra": ", min=1.0, max=0.0"}, ["min 1.0 is above max 0.0"]),
    ("start-outside", {"start": "5.0", "extra": ", min=0.0, max=1.0"}, ["start 5.0 lies outside"]),
    ("start-text", {"start": "'abc'"}, ["could not convert string to float"]),
    ("start-beyond-float", {"start": "10**400"}, ["OverflowError"]),
    ("two-classes", {"after": "\n\nclass Other(Law):\n    def do_step(self, t, dt):\n        return True\n"},
     ["defines 2 FMU classes: Law (line", "Other (line"]),
    ("exit-0-at-import", {"before": "import sys\nsys.exit(0)\n"}, ["line 2: importing it called sys.exit(0)"]),
    ("exit-3-at-import", {"before": "import sys\nsys.exit(3)\n"}, ["importing it called sys.exit(3)"]),
    ("os-exit-at-import", {"before": "import os\nos._exit(0)\n"}, ["it called os._exit(0)"]),
    ("ctrl-c-at-import", {"before": "raise KeyboardInterrupt\n"}, ["importing it raised KeyboardInterrupt"]),
    ("input-at-import", {"before": "input('gain? ')\n"}, ["EOFError"]),
    ("exit-in-init", {"init": "import sys; sys.exit(0)"}, ["instantiating Law called sys.exit(0)"]),
    ("raise-in-init", {"init": "raise ValueError('no gain')"}, ["instantiating Law raised ValueError: no gain"]),
    ("no-file-descriptors", {"before": "import resource\nresource.setrlimit(resource.RLIMIT_NOFILE, (3, 3))\n"},
     ["the child process importing it ended with status"]),
    ("imports-a-missing-module", {"before": "import not_a_module_anywhere\n"}, ["ModuleNotFoundError"]),
]:
    case(f"law-{name}", SOURCES, "cli", ["build-fmus", "{home}/L.py", "--out", "{out}"], "bad", "{home}/L.py",
         *fragments, setup=law("L", **pieces))
for name, pieces, fragment, fixed in [
    ("start-nan", {"start": "float('nan')"}, "gain: start nan is not a number",
     "built; its first run failed at another component's non-finite output (exit 1)"),
    ("unit-none", {"unit": None}, "gain: unit None is not a text", "TypeError: object of type 'NoneType' has no len()"),
    ("unit-number", {"unit": 5}, "gain: unit 5 is not a text", "TypeError: object of type 'int' has no len()")]:
    case(f"law-{name}", SOURCES, "cli", ["build-fmus", "{home}/L.py", "--out", "{out}"], "bad", fragment,
         setup=law("L", **pieces), fixed=fixed)
for name, content, fragments in [
    ("utf16", law_source().encode("utf-16"), ["byte 0xff is not valid utf-8"]),
    ("latin1-comment", b"# caf\xe9\n" + law_source().encode(), ["line 1: SyntaxError: byte 0xe9 is not valid utf-8"]),
    ("unknown-coding", b"# -*- coding: klingon -*-\n" + law_source().encode(), ["unknown encoding: klingon"]),
    ("nul-byte", law_source().encode() + b"\x00", ["null bytes"]),
    ("empty", b"", ["defines no concrete FMU class"]),
    ("json-not-python", b'{"a": 1}\n', ["defines no concrete FMU class"]),
]:
    case(f"law-{name}", SOURCES, "cli", ["build-fmus", "{home}/L.py", "--out", "{out}"], "bad", *fragments,
         setup=text_file("L.py", content))
for name, setup, fragments in [("symlink-to-itself", symlink("L.py", "L.py"), ["symlink loop"]),
                               ("dangling-symlink", symlink("L.py", "nowhere.py"), ["file not found"]),
                               ("fifo", fifo("L.py"), ["not a regular file"]),
                               ("folder", folder("L.py"), ["is a folder"]),
                               ("missing", None, ["file not found"])]:
    case(f"law-{name}", SOURCES, "cli", ["build-fmus", "{home}/L.py"], "bad", "L.py", *fragments, setup=setup)
case("law-hangs-at-import", SOURCES, "cli", ["build-fmus", "{home}/L.py"], "bad", "took more than 2 s",
     "the child process was killed", setup=law("L", before="while True:\n    pass\n"), import_limit=2.0)
case("law-hangs-in-init", SOURCES, "cli", ["build-fmus", "{home}/L.py"], "bad", "took more than 2 s",
     setup=law("L", init="while True: pass"), import_limit=2.0, slow=True)
case("law-starts-a-process-at-import", SOURCES, "cli", ["build-fmus", "{home}/L.py", "--out", "{out}"], "ok",
     setup=law("L", before="import subprocess\nsubprocess.Popen(['sleep', '300'])\n"), fmus=True)
case("law-file-name-with-a-dot", SOURCES, "cli", ["run", "{home}/s_law.v2.json", "--out", "{out}", "--no-plots"], "ok",
     "completed", setup=flown("law.v2"), fmus=True,
     fixed="built, then every run failed at instantiation: ModuleNotFoundError: No module named 'law'")
case("law-file-name-with-a-space", SOURCES, "cli", ["run", "{home}/s_my law.json", "--out", "{out}", "--no-plots"],
     "ok", "completed", setup=flown("my law"), fmus=True)
case("law-as-fmi2-of-a-pythonfmu3-class", SOURCES, "cli", ["build-fmus", "{home}/G.py", "--fmi", "2"], "bad",
     "a pythonfmu3 class builds as FMI 3.0 only",
     setup=lambda sb: write(sb.home / "G.py", __import__("tests.helper_fmus.pythonfmu3_gain").helper_fmus
                            .pythonfmu3_gain.SOURCE))

# the law contract when it runs: the user's file and line, never exit 0 for a broken law
for name, pieces, expect, fragments, fixed in [
    ("returns-none", {"body": "pass"}, "failed", ["do_step returned None", "(a missing `return`?)"], ""),
    ("returns-false", {"body": "return current_time < 2.0"}, "failed", ["refused the step at t = 2.0 s"], ""),
    ("raises", {"body": "raise ValueError('math domain error')"}, "failed",
     ["L.py, line", "ValueError: math domain error"], ""),
    ("calls-sys-exit", {"body": "import sys\n                sys.exit(0)"}, "failed", ["SystemExit(0)"], ""),
    ("calls-os-exit", {"body": "import os\n                os._exit(0)"}, "failed",
     ["os._exit(0) was called; an FMU must not end the process"],
     "the command ended with exit 0, no summary.json (the law ended the process)"),
    ("raises-keyboard-interrupt", {"body": "raise KeyboardInterrupt"}, "failed", ["KeyboardInterrupt"], ""),
    ("ignores-sigint-and-returns", {"body": "import signal\n                signal.signal(signal.SIGINT, "
                                            "signal.SIG_IGN)\n                return True"}, "ok", ["completed"], ""),
]:
    case(f"step-{name}", CONTRACT, "cli", ["run", "{home}/s_L.json", "--out", "{out}", "--no-plots"], expect,
         *fragments, setup=flown("L", **pieces), fmus=True, fixed=fixed)
case("step-hangs-under-a-limit", CONTRACT, "cli", ["run", "{home}/s_L.json", "--out", "{out}", "--no-plots",
                                                   "--step-timeout", "0.5"], "failed", "step timeout",
     setup=flown("L", body="while True: pass"), fmus=True)
case("step-fails-every-campaign-run", CONTRACT, "cli", ["montecarlo", "{home}/m.json", "--runs", "3", "--out", "{out}"],
     "failed", "none of the 3 runs completed", "failures.jsonl", fmus=True,
     setup=both(flown("L", body="raise ValueError('always')"),
                lambda sb: write(sb.home / "m.json", json.dumps({
                    "system": "w_L.json", "stop": 10.0, "step": 0.5, "dispersions": {
                        "vehicle.h0": {"distribution": "uniform", "low": 89000.0, "high": 91000.0}}}))))

# signals: SIGINT and SIGTERM at every phase, once and twice
INT, TERM = signal.SIGINT, signal.SIGTERM
for name, args, setup, signals, fragments, fixed in [
    ("build-sigint", ["build-fmus", "{home}/L.py", "--out", "{out}"], marker_law("L", "import"), ((marked, INT),),
     ["interrupted by SIGINT"], ""),
    ("build-sigterm", ["build-fmus", "{home}/L.py", "--out", "{out}"], marker_law("L", "import"), ((marked, TERM),),
     ["interrupted by SIGTERM"], "killed at once: the source-check child left running, its temporary folder left"),
    ("build-sigint-twice", ["build-fmus", "{home}/L.py", "--out", "{out}"], marker_law("L", "import"),
     ((marked, INT), (later(0.5), INT)), ["interrupted by SIGINT"], ""),
    ("run-build-sigint", ["run", "{home}/s_L.json", "--out", "{out}"], marker_law("L", "import"), ((marked, INT),),
     [], "Ctrl-C ignored until the source check's time limit (60 s)"),
    ("run-instantiate-sigint", ["run", "{home}/s_L.json", "--out", "{out}"], marker_law("L", "instantiate"),
     ((marked, INT),), [], "Ctrl-C ignored while the FMU's __init__ slept"),
    ("run-instantiate-sigterm", ["run", "{home}/s_L.json", "--out", "{out}"], marker_law("L", "instantiate"),
     ((marked, TERM),), [], "SIGTERM ignored while the FMU's __init__ slept"),
    ("run-hung-step-sigint-twice", ["run", "{home}/s_L.json", "--out", "{out}", "--no-plots"], marker_law("L", "step"),
     ((marked, INT), (later(0.5), INT)), ["interrupted"], "hung: both Ctrl-C only recorded, the step never returned"),
    ("run-hung-step-sigterm-sigint", ["run", "{home}/s_L.json", "--out", "{out}", "--no-plots"],
     marker_law("L", "step"), ((marked, TERM), (later(0.5), INT)), ["interrupted"], "hung"),
    ("mc-sigint", ["montecarlo", "{MC}", "--runs", "400", "--out", "{out}", "--workers", "2"], None,
     ((rows_written, INT),), ["finished runs kept"], ""),
    ("mc-sigterm-twice", ["montecarlo", "{MC}", "--runs", "400", "--out", "{out}", "--workers", "2"], None,
     ((rows_written, TERM), (later(0.5), TERM)), ["finished runs kept"], ""),
    ("bench-sigint", ["benchmark", "{home}/set", "--runs", "300", "--out", "{out}", "--workers", "2", "--refly"],
     small_set, ((lambda sb: rows_written(sb, "out/robust"), INT),), ["no scorecard written"], ""),
    ("sweep-sigint", ["sweep", "{P}", "--grid", "vehicle.gamma0=-0.03:-0.01:400", "--out", "{out}"], None,
     ((lambda sb: (sb.out / ".lock").exists(), INT),), [], ""),
    ("corridor-sigint", ["corridor", "{P}", "--lift-to-drag", "0.3", "--tolerance", "0.001", "--out", "{out}"], None,
     ((lambda sb: (sb.out / "lift_up.json").exists(), INT),), ["no corridor.json written"], ""),
]:
    case(name, SIGNALS, "process", args, "interrupted", *fragments, setup=setup, signals=signals, fmus=True,
         slow=name not in ("build-sigterm", "run-hung-step-sigint-twice"), fixed=fixed, limit=60.0,
         then=pid_gone if name.startswith(("build-", "run-build-")) else None)  # the source check's child

# resource limits
def _file_size_limit():
    import resource

    resource.setrlimit(resource.RLIMIT_FSIZE, (20000, 20000))


case("run-file-size-limit", RESOURCES, "process", ["run", "{N}", "--out", "{out}", "--no-plots"], "failed",
     "cannot write timeseries.csv.part: File too large", fmus=True, preexec=_file_size_limit)
case("mc-workers-per-core", RESOURCES, "cli", ["montecarlo", "{MC}", "--runs", "2", "--out", "{out}", "--workers",
                                               str(4 * len(os.sched_getaffinity(0)) + 1)], "bad",
     "give at most 4 per usable core")
case("run-too-many-steps", RESOURCES, "cli", ["run", "{N}", "--out", "{out}", "--stop", "1e9", "--step", "0.1",
                                              "--no-plots", "--step-timeout", "1e300"], "bad", "communication points",
     fmus=True)
case("mc-step-limit-huge", RESOURCES, "cli", ["montecarlo", "{MC}", "--runs", "2", "--out", "{out}",
                                              "--step-timeout", "1e300", "--stop", "20"], "ok", fmus=True)

def tmpfs(name: str, options: str):
    """setup: home/<name>, a tmpfs mounted with `options` ("size=64k", "ro"), unmounted after the
    case; the case is skipped where no tmpfs can be mounted (not root)."""
    def setup(sb):
        import subprocess

        import pytest

        mount = sb.home / name
        mount.mkdir()
        if subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(mount)], capture_output=True,
                          check=False).returncode:
            pytest.skip("cannot mount a tmpfs here")
        sb.extra.setdefault("cleanups", []).append(
            lambda: subprocess.run(["umount", str(mount)], check=True))
    return setup


for name, args, expect, fragment, fixed in [
    ("build-fmus", ["build-fmus", "LiftActuator", "--out", "{home}/full/fmus"], "bad", "cannot write LiftActuator.fmu",
     "exit 3 (OSError), a cut LiftActuator.fmu and .aotv-written.part left"),
    ("montecarlo", ["montecarlo", "{MC}", "--runs", "50", "--out", "{home}/full/mc", "--keep-series"], "failed",
     "No space left on device", "exit 3 (OSError from pyarrow), .aotv-written.part and series.parquet.part left"),
    ("sweep", ["sweep", "{P}", "--grid", "vehicle.gamma0=-0.03:-0.01:300", "--out", "{home}/full/sw"], "failed",
     "No space left on device", "exit 3 (OSError)"),
    ("export-ssp", ["export-ssp", "{N}", "-o", "{home}/full/x.ssp"], "bad", "cannot write the archive", ""),
    ("run", ["run", "{N}", "--out", "{home}/full/run", "--no-plots", "--step", "0.01"], "failed",
     "No space left on device", "")]:
    case(f"full-disk-{name}", RESOURCES, "cli", args, expect, fragment, setup=tmpfs("full", "size=192k"), fmus=True,
         fixed=fixed)
for name, args in [("build-fmus", ["build-fmus", "LiftActuator", "--out", "{home}/ro"]),
                   ("montecarlo", ["montecarlo", "{MC}", "--runs", "2", "--out", "{home}/ro"]),
                   ("export-ssp", ["export-ssp", "{N}", "-o", "{home}/ro/x.ssp"])]:
    case(f"read-only-{name}", RESOURCES, "cli", args, "bad", "ead-only file system", setup=tmpfs("ro", "ro,size=64k"),
         fmus=True)

# Dask schedulers
for name, address, fragments in [("refused", "tcp://127.0.0.1:1", ["cannot reach the Dask scheduler"]),
                                 ("ipv6-refused", "tcp://[::1]:1", ["cannot reach"]),
                                 ("no-port", "foo", ["cannot read the scheduler address"]),
                                 ("port-out-of-range", "tcp://127.0.0.1:99999", ["cannot read the scheduler address"]),
                                 ("empty-host", "tcp://", ["cannot read the scheduler address"]),
                                 ("spaces", "tcp://a b:1", ["expected a Dask scheduler address"])]:
    case(f"scheduler-{name}", DASK, "cli", ["montecarlo", "{MC}", "--runs", "2", "--out", "{out}", "--scheduler",
                                            address],
         "bad", "--scheduler", *fragments)
for name, address in [("inproc", "inproc://x"), ("ucx", "ucx://127.0.0.1:1")]:
    case(f"scheduler-{name}", DASK, "cli", ["sweep", "{P}", "--grid", "vehicle.gamma0=-0.02", "--out", "{out}",
                                            "--scheduler", address], "bad", "cannot connect to the Dask scheduler",
         fmus=True, fixed="exit 3 (ValueError / TypeError from inside distributed)")
case("scheduler-unroutable", DASK, "cli", ["montecarlo", "{MC}", "--runs", "2", "--out", "{out}", "--scheduler",
                                           "tcp://10.255.255.1:8786"], "bad", "--scheduler", slow=True)


def tcp_server(greeting: bytes):
    """setup: a TCP server on this machine (its address is {server}) that answers each connection
    with `greeting` (b"": nothing, as a web server that waits for a request), closed after the case."""
    def setup(sb):
        import socketserver
        import threading

        class Handler(socketserver.BaseRequestHandler):
            def handle(self):
                if greeting:
                    self.request.sendall(greeting)
                self.request.settimeout(10)
                with contextlib.suppress(OSError):
                    self.request.recv(1 << 16)

        server = socketserver.ThreadingTCPServer(("127.0.0.1", 0), Handler)
        server.daemon_threads = True
        threading.Thread(target=server.serve_forever, daemon=True).start()
        sb.extra["server"] = f"tcp://127.0.0.1:{server.server_address[1]}"
        sb.extra["stop_server"] = server
    return setup


def stop_server(sb):
    server = sb.extra["stop_server"]
    server.shutdown()
    server.server_close()


for name, greeting, fixed in [
    ("a-dashboard", b"", "hung, deaf to Ctrl-C: Dask's client waited for a handshake a web server never sends"),
    ("an-ssh-server", b"SSH-2.0-OpenSSH_9.6\r\n",
     "exit 3 (MemoryError: Dask read a frame length of exabytes from the server's text)")]:
    case(f"scheduler-is-{name}", DASK, "cli", ["montecarlo", "{MC}", "--runs", "2", "--out", "{out}", "--scheduler",
                                               "{server}"], "bad", "does not answer as a Dask scheduler",
         setup=tcp_server(greeting), then=stop_server, fixed=fixed, slow=not greeting)


def _client_campaign(sb):
    """A campaign on the user's own distributed.Client (its scratch space kept out of the package's
    temporary folder, which the harness watches)."""
    import dask
    from distributed import Client, LocalCluster

    with dask.config.set({"temporary-directory": str(sb.root / "dask")}), \
            LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        return _aotv().montecarlo(_p(sb, MC), 2, scheduler=client, stop=20.0)


case("scheduler-client-object", DASK, "api", _client_campaign, "ok", fmus=True, slow=True)

# FMI 3.0 surfaces
case("fmi3-export-over-the-scenario", FMI3, "cli", ["export-ssp", "{home}/s.json", "-o", "{home}/s.json", "--fmi", "3"],
     "bad", "was not written by aotv-cosim", setup=lambda sb: nominal_copy(sb, "s.json"),
     fixed="the scenario replaced by the archive")
case("fmi3-build-law-hangs", FMI3, "cli", ["build-fmus", "{home}/L.py", "--fmi", "3"], "bad", "took more than 2 s",
     setup=law("L", before="while True:\n    pass\n"), import_limit=2.0, slow=True)
case("fmi3-build-law-km", FMI3, "cli", ["build-fmus", "{home}/L.py", "--fmi", "3"], "bad", "'km' is not an SI unit",
     setup=law("L", unit="km"))
PYTHONFMU3 = textwrap.dedent('''
    from pythonfmu3 import Fmi3Causality, Fmi3Slave, Fmi3Variability, Float64


    class G3(Fmi3Slave):
        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.k = 1.0
            self.register_variable(Float64("k", causality=Fmi3Causality.parameter, variability=Fmi3Variability.fixed,
                                           unit="1"))

        def do_step(self, current_time, step_size):
            {body}
''')
for name, before, after, fragments in [
    ("exit", "import sys\nsys.exit(0)\n", "", ["importing it called sys.exit(0)"]),
    ("os-exit", "import os\nos._exit(0)\n", "", ["it called os._exit(0)"]),
    ("two-classes", "", "\n\nclass G4(G3):\n    def do_step(self, t, dt):\n        return True\n",
     ["defines 2 FMU classes: G3 (line"]),
]:
    case(f"fmi3-pythonfmu3-{name}", FMI3, "cli", ["build-fmus", "{home}/G.py", "--out", "{out}"], "bad", *fragments,
         setup=text_file("G.py", before + PYTHONFMU3.format(body="return True") + after),
         fixed="pythonfmu3's builder ran the file in the command's process: sys.exit(0) ended build-fmus with exit 0 "
               "and no FMU; a second class was not refused")
case("fmi3-pythonfmu3-returns-none", FMI3, "cli", ["run", "{home}/s.json", "--out", "{out}", "--no-plots"], "failed",
     "G3.do_step returned None", fmus=True,
     setup=lambda sb: (write(sb.home / "G.py", PYTHONFMU3.format(body="pass")),
                       write(sb.home / "w.json", json.dumps({"components": {"g": {"fmu": "G.py"}}, "connections": []})),
                       write(sb.home / "s.json", json.dumps({"system": "w.json", "stop": 1.0, "step": 0.5}))),
     fixed="'terminated ... 0 steps', exit 0 (None taken for a refused step, then for a terminate request)")
case("fmi3-crafted-fmu-no-cosimulation", FMI3, "cli", ["validate", "{home}/w.json"], "bad", "components.g.fmu",
     setup=lambda sb: (write(sb.home / "m3.fmu", _zip({"modelDescription.xml": (
         '<?xml version="1.0" encoding="UTF-8"?><fmiModelDescription fmiVersion="3.0" modelName="m" '
         'instantiationToken="{x}"><ModelVariables/><ModelStructure/></fmiModelDescription>')})),
                       write(sb.home / "w.json", json.dumps({"components": {"g": {"fmu": "m3.fmu"}},
                                                             "connections": []}))))
case("fmi3-crafted-fmu-bad-xml", FMI3, "cli", ["validate", "{home}/w.json"], "bad", "components.g.fmu",
     setup=lambda sb: (write(sb.home / "m3.fmu",
                             _zip({"modelDescription.xml": '<fmiModelDescription fmiVersion="3.0"'})),
                       write(sb.home / "w.json", json.dumps({"components": {"g": {"fmu": "m3.fmu"}},
                                                             "connections": []}))))


def _zip(members: dict) -> bytes:
    import io
    import zipfile

    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        for name, text in members.items():
            archive.writestr(name, text)
    return buffer.getvalue()


# repeated calls and threads from Python
def _runs_again_and_again(sb):
    import os as os_

    before = len(os_.listdir("/proc/self/fd"))
    for _ in range(10):
        assert _aotv().run(_p(sb, N), stop=2.0).status == "completed"
    assert len(os_.listdir("/proc/self/fd")) <= before + 2, "file descriptors grow with each run"


def _in_a_thread(call):
    def run(sb):
        import threading

        found = []
        thread = threading.Thread(target=lambda: found.append(call(sb)))
        thread.start()
        thread.join(120)
        assert found, "the call in the thread did not return"
        return found[0]
    return run


def _two_threads(sb):
    import threading

    alone = _aotv().run(_p(sb, N), stop=20.0).timeseries
    results = []
    threads = [threading.Thread(target=lambda: results.append(_aotv().run(_p(sb, N), stop=20.0).timeseries))
               for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(120)
    assert len(results) == 2 and all(r.equals(alone) for r in results)


def _bad_then_good(sb):
    from aotv_cosim.errors import InputError

    for _ in range(3):
        with contextlib.suppress(InputError):
            _aotv().run(_p(sb, N), stop=-5.0)
    assert _aotv().run(_p(sb, N), stop=1.0).status == "completed"


for name, call in [("run-ten-times", _runs_again_and_again), ("two-threads-at-once", _two_threads),
                   ("bad-input-then-a-run", _bad_then_good),
                   ("run-in-a-thread-with-a-step-limit", _in_a_thread(lambda sb: _aotv().run(_p(sb, N), stop=5.0,
                                                                                            step_timeout=1.0))),
                   ("campaign-in-a-thread", _in_a_thread(lambda sb: _aotv().montecarlo(_p(sb, MC), 2, workers=2,
                                                                                       stop=20.0))),
                   ("sweep-in-a-thread", _in_a_thread(lambda sb: _aotv().sweep(_p(sb, P), {"vehicle.gamma0": [-0.02]},
                                                                               workers=1)))]:
    case(name, REPEATED, "api", call, "ok", fmus=True)
case("bad-input-in-a-thread", REPEATED, "api", _in_a_thread(lambda sb: _catch(lambda: _aotv().montecarlo(
    _p(sb, MC), 0))), "ok")


def _catch(call):
    from aotv_cosim.errors import InputError

    try:
        call()
    except InputError as exc:
        return str(exc)
    raise AssertionError("no InputError")


# ---- the table of docs/reliability.md ---------------------------------------------------------
CATEGORIES = (OPTIONS_CLI, OPTIONS_API, SETS, PATHS, FILES, SOURCES, CONTRACT, SIGNALS, RESOURCES, DASK, FMI3, REPEATED)
OUTCOMES = {"bad": "exit 2 / InputError, one line", "ok": "exit 0 (valid input)", "failed": "exit 1 (the run fails)",
            "interrupted": "exit 130 / 143"}


def table() -> str:
    """The markdown table of the corpus: per category, its cases, their outcomes, and what was
    fixed (the `fixed` texts of its cases, by case)."""
    lines = ["| category | cases | outcomes | failed before this corpus's fixes (now as the outcome says) |",
             "|---|---|---|---|"]
    for category in CATEGORIES:
        cases = [c for c in CASES if c.category == category]
        counts = {o: sum(c.expect == o for c in cases) for o in OUTCOMES}
        shown = ", ".join(f"{n} {OUTCOMES[o]}" for o, n in counts.items() if n)
        fixed = "; ".join(f"`{c.name}`: {c.fixed}" for c in cases if c.fixed) or "-"
        lines.append(f"| {category} | {len(cases)} | {shown} | {fixed} |")
    total = len(CASES)
    lines.append(f"| all | {total} | {sum(c.expect == 'bad' for c in CASES)} bad input, "
                 f"{sum(c.expect != 'bad' for c in CASES)} other | {sum(bool(c.fixed) for c in CASES)} fixed |")
    return "\n".join(lines)


if __name__ == "__main__":
    print(table())
