"""One front door (issue 34 item 1): every option of every command is checked in one place
(`aotv_cosim.options`), so the command line and the Python API refuse the same bad value with the
same line, before anything is loaded, built, run or written; the command line only parses into
the options object and the API's keywords build the same object, with the same defaults but for
the number of workers; every call holds the one-call-at-a-time lock.

None of these cases needs a built FMU: the refusal comes before the scenario is loaded."""

import dataclasses
import math

import pytest

import aotv_cosim
from aotv_cosim import api, cli, options
from aotv_cosim.errors import InputError
from aotv_cosim.options import checks
from tests.helpers import NOMINAL, SCENARIOS, error_lines, invoke

MC = SCENARIOS / "montecarlo_robust_density.json"
SET = SCENARIOS / "benchmark_seed000"
PASS = SET / "time_linear.json"


def _refused(call, *fragments):
    """The API's InputError of call(), holding every fragment; returns its line."""
    with pytest.raises(InputError) as caught:
        call()
    line = str(caught.value)
    for fragment in fragments:
        assert fragment in line, line
    assert "; " in line and "\n" not in line, line
    return line


def _cli_refused(args, *fragments, tmp_path=None):
    """Exit 2 and one line `error: ...` holding every fragment, and nothing written in --out."""
    status, text = invoke(*args)
    assert status == 2, text
    lines = error_lines(text)
    assert len(lines) == 1 and "Traceback" not in text, text
    for fragment in fragments:
        assert fragment in lines[0], lines[0]
    return lines[0]


# (API call, command line, fragments of the one line both give); each was a defect of issue 34
CASES = [
    ("step timeout nan", lambda out: aotv_cosim.montecarlo(MC, 2, step_timeout=math.nan, out=out),
     ["montecarlo", MC, "--runs", "2", "--step-timeout", "nan"], ["--step-timeout", "the time limit nan s"]),
    ("step timeout inf", lambda out: aotv_cosim.montecarlo(MC, 2, step_timeout=math.inf, out=out),
     ["montecarlo", MC, "--runs", "2", "--step-timeout", "inf"], ["--step-timeout", "the time limit inf s"]),
    ("max rss nan", lambda out: aotv_cosim.montecarlo(MC, 2, max_rss=math.nan, out=out),
     ["montecarlo", MC, "--runs", "2", "--max-rss", "nan"], ["--max-rss", "the memory limit nan MiB"]),
    ("max rss inf", lambda out: aotv_cosim.montecarlo(MC, 2, max_rss=math.inf, out=out),
     ["montecarlo", MC, "--runs", "2", "--max-rss", "inf"], ["--max-rss", "the memory limit inf MiB"]),
    ("runs 0", lambda out: aotv_cosim.montecarlo(MC, 0, out=out),
     ["montecarlo", MC, "--runs", "0"], ["--runs", "runs 0 is outside 1..1000000"]),
    ("workers 0", lambda out: aotv_cosim.montecarlo(MC, 2, workers=0, out=out),
     ["montecarlo", MC, "--runs", "2", "--workers", "0"], ["--workers", "workers 0 is outside 1.."]),
    ("workers 10000", lambda out: aotv_cosim.montecarlo(MC, 2, workers=10000, out=out),
     ["montecarlo", MC, "--runs", "2", "--workers", "10000"], ["--workers", "workers 10000 is outside 1.."]),
    ("seed -1", lambda out: aotv_cosim.montecarlo(MC, 2, seed=-1, out=out),
     ["montecarlo", MC, "--runs", "2", "--seed", "-1"], ["--seed", "seed -1 is outside 0.."]),
    ("benchmark runs 0", lambda out: aotv_cosim.benchmark(SET, runs=0, out=out),
     ["benchmark", SET, "--runs", "0"], ["--runs", "runs 0 is outside"]),
    ("benchmark runs 1e9", lambda out: aotv_cosim.benchmark(SET, runs=10**9, out=out),
     ["benchmark", SET, "--runs", "1000000000"], ["--runs", "runs 1000000000 is outside 1..1000000"]),
    ("sweep step timeout nan", lambda out: aotv_cosim.sweep(PASS, ["vehicle.gamma0=-0.03:-0.01:3"],
                                                            step_timeout=math.nan, out=out),
     ["sweep", PASS, "--grid", "vehicle.gamma0=-0.03:-0.01:3", "--step-timeout", "nan"], ["--step-timeout"]),
    ("sweep max rss 0", lambda out: aotv_cosim.sweep(PASS, ["vehicle.gamma0=-0.03:-0.01:3"], max_rss=0, out=out),
     ["sweep", PASS, "--grid", "vehicle.gamma0=-0.03:-0.01:3", "--max-rss", "0"], ["--max-rss"]),
    ("corridor bracket past the vertical", lambda out: aotv_cosim.corridor(PASS, lift_to_drag=5, bracket=(-3, -0.002),
                                                                           out=out),
     ["corridor", PASS, "--lift-to-drag", "5", "--bracket", "-3", "-0.002"],
     ["--bracket", "the bracket (-3.0, -0.002) rad is not a finite range", "-pi/2 < STEEP < SHALLOW < 0"]),
    ("corridor bracket above the horizon", lambda out: aotv_cosim.corridor(PASS, lift_to_drag=5, bracket=(-0.08, 0.01),
                                                                           out=out),
     ["corridor", PASS, "--lift-to-drag", "5", "--bracket", "-0.08", "0.01"], ["--bracket"]),
    ("corridor workers 0", lambda out: aotv_cosim.corridor(PASS, lift_to_drag=5, workers=0, out=out),
     ["corridor", PASS, "--lift-to-drag", "5", "--workers", "0"], ["--workers"]),
    ("run step nan", lambda out: aotv_cosim.run(NOMINAL, step=math.nan, out=out),
     ["run", NOMINAL, "--step", "nan"], ["--step", "the step nan s"]),
    ("run stop inf", lambda out: aotv_cosim.run(NOMINAL, stop=math.inf, out=out),
     ["run", NOMINAL, "--stop", "inf"], ["--stop", "the stop inf s"]),
    ("run step timeout nan", lambda out: aotv_cosim.run(NOMINAL, step_timeout=math.nan, out=out),
     ["run", NOMINAL, "--step-timeout", "nan"], ["--step-timeout"]),
]


@pytest.mark.parametrize("name, call, args, fragments", CASES, ids=[c[0] for c in CASES])
def test_both_faces_refuse_a_bad_option_with_the_same_line_before_anything_is_written(name, call, args,
                                                                                      fragments, tmp_path):
    api_line = _refused(lambda: call(tmp_path / "api"), *fragments)
    cli_line = _cli_refused([*args, "--out", tmp_path / "cli"], *fragments)
    assert cli_line == f"error: {api_line}".replace(str(tmp_path / "api"), str(tmp_path / "cli"))
    assert not (tmp_path / "api").exists() and not (tmp_path / "cli").exists()


def test_the_api_refuses_wrong_types_with_one_line_not_a_traceback_from_deep_inside():
    """run(None), run(set="a.b=1"), montecarlo(runs="2"), bools for integers: TypeError or
    ValueError from inside before; now the InputError the documentation promises."""
    _refused(lambda: aotv_cosim.run(None), "SCENARIO", "expected the path of scenario file", "got None")
    _refused(lambda: aotv_cosim.run(NOMINAL, set="a.b=1"), "--set", "expected a mapping", "got 'a.b=1' (str)")
    _refused(lambda: aotv_cosim.run(NOMINAL, set={"h0": 1.0}), "--set", "no component.variable")
    _refused(lambda: aotv_cosim.run(NOMINAL, set={"vehicle.h0": math.nan}), "--set", "not a finite number")
    _refused(lambda: aotv_cosim.montecarlo(MC, "2"), "--runs", "runs must be an integer, got '2' (str)")
    _refused(lambda: aotv_cosim.montecarlo(MC, True), "--runs", "got True (bool)")
    _refused(lambda: aotv_cosim.montecarlo(MC, 2, workers=2.0), "--workers", "must be an integer")
    _refused(lambda: aotv_cosim.montecarlo(MC, 2, keep_series=1), "--keep-series", "expected True or False")
    _refused(lambda: aotv_cosim.montecarlo(MC, 2, scheduler=""), "--scheduler", "expected a Dask scheduler address")
    _refused(lambda: aotv_cosim.montecarlo(MC, 2, resume=True), "--resume", "needs the folder")
    _refused(lambda: aotv_cosim.montecarlo(MC, 2, fmi_calls="fast"), "--fmi-calls", "unknown value 'fast'")
    _refused(lambda: aotv_cosim.run(NOMINAL, formats=("csv", "hdf5")), "--format", "'hdf5'")
    _refused(lambda: aotv_cosim.sweep(PASS, "vehicle.gamma0=1:2:3"), "--grid", "expected grids")
    _refused(lambda: aotv_cosim.sweep(PASS, {"vehicle.gamma0": []}), "--grid", "has no value")
    _refused(lambda: aotv_cosim.sweep(PASS, {"vehicle.gamma0": [0.1, math.inf]}), "--grid", "not a finite number")
    _refused(lambda: aotv_cosim.corridor(PASS, lift_to_drag=math.nan), "--lift-to-drag", "L/D nan")
    _refused(lambda: aotv_cosim.corridor(PASS, lift_to_drag=5, bracket=(-0.08,)), "--bracket", "two numbers")
    _refused(lambda: aotv_cosim.describe(None), "FMU|WIRING", "got None")
    _refused(lambda: aotv_cosim.build_fmus(42), "NAME|SOURCE.py", "got 42")
    _refused(lambda: api.execute(None), "options", "not an options object")


def test_one_law_given_alone_is_one_law_not_its_letters(tmp_path):
    """benchmark(set, "mine.json") read the string letter by letter ('m', 'i', ...)."""
    assert options.BenchmarkOptions(scenario_set=SET, laws=str(NOMINAL)).laws == (NOMINAL,)
    assert options.BenchmarkOptions(scenario_set=SET, laws=NOMINAL).laws == (NOMINAL,)
    assert options.BuildOptions(sources="Atmosphere").sources == (checks.Path("Atmosphere"),)
    assert options.RunOptions(scenario=NOMINAL, formats="parquet").formats == ("parquet",)
    missing = tmp_path / "mine.json"
    line = _refused(lambda: aotv_cosim.benchmark(SET, str(missing), runs=2), f"{missing}: --law: file not found")
    assert _cli_refused(["benchmark", SET, "--law", missing, "--runs", "2"]) == f"error: {line}"


def test_a_law_file_whose_name_aliases_the_folder_structure_is_refused(tmp_path):
    """A law named '.' (file `..json`) made its campaign folder the output folder itself, and a
    later --refly deleted everything there; 'laws' collided with the generated scenarios' folder."""
    for name in ("..json", "...json", "laws.json", "LAWS.json", "rows.json", "scorecard.json", ".hidden.json"):
        law = tmp_path / name
        law.write_text("{}")
        line = _refused(lambda law=law: aotv_cosim.benchmark(SET, law, runs=2, out=tmp_path / "o"),
                        "--law", "would alias the benchmark folder's own files or folders", "rename the file")
        args = ["benchmark", SET, "--law", law, "--runs", "2", "--out", tmp_path / "o"]
        assert _cli_refused(args) == f"error: {line}"
    assert not (tmp_path / "o").exists()


def test_every_call_holds_the_one_call_lock(monkeypatch):
    """The README promises calls from several threads run one at a time: every command's
    implementation runs with the lock held (it covered run and montecarlo only)."""
    held = {}

    def note(opts, **_):
        held[type(opts)] = api._ONE_AT_A_TIME._is_owned()

    for kind in list(api._COMMANDS):
        monkeypatch.setitem(api._COMMANDS, kind, note)
    aotv_cosim.run(NOMINAL)
    aotv_cosim.montecarlo(MC, 2)
    aotv_cosim.benchmark(SET, runs=2)
    aotv_cosim.sweep(PASS, {"vehicle.gamma0": [-0.02]})
    aotv_cosim.corridor(PASS, lift_to_drag=5)
    aotv_cosim.describe("Atmosphere")
    aotv_cosim.build_fmus("Atmosphere")
    aotv_cosim.validate(NOMINAL)
    aotv_cosim.export_ssp(NOMINAL, "x.ssp")
    assert set(held) == set(api._COMMANDS) - {options.CheckOptions, options.CompareOptions}
    assert all(held.values())


def _cli_options(monkeypatch, *args):
    """The options object the command line builds for `aotv-cosim ARGS` (not executed)."""
    built = []

    def capture(opts, **_):
        built.append(opts)
        raise SystemExit(0)

    monkeypatch.setattr(cli, "_execute", capture)
    status, text = invoke(*args)
    assert status == 0 and built, text
    return built[0]


def _api_options(monkeypatch, call):
    built = []

    def capture(opts, **_):
        built.append(opts)

    monkeypatch.setattr(api, "execute", capture)
    call()
    return built[0]


SAME = [("montecarlo", ["montecarlo", MC, "--runs", "5"], lambda: api.montecarlo(MC, 5)),
        ("benchmark", ["benchmark", SET], lambda: api.benchmark(SET)),
        ("sweep", ["sweep", PASS, "--grid", "vehicle.gamma0=-0.02"], lambda: api.sweep(PASS, ["vehicle.gamma0=-0.02"])),
        ("corridor", ["corridor", PASS, "--lift-to-drag", "5"], lambda: api.corridor(PASS, lift_to_drag=5)),
        ("run", ["run", NOMINAL], lambda: api.run(NOMINAL))]


@pytest.mark.parametrize("name, args, call", SAME, ids=[s[0] for s in SAME])
def test_both_faces_build_the_same_options_with_the_same_defaults(name, args, call, monkeypatch):
    """What differs is documented: workers (1 on the command line, every core in Python), the output
    folder (the command line always writes one), the plots a run draws there, the progress bar."""
    from_cli = _cli_options(monkeypatch, *args)
    from_api = _api_options(monkeypatch, call)
    assert type(from_cli) is type(from_api)
    exempt = {"workers", "out", "plots", "progress"}
    differ = {f.name for f in dataclasses.fields(from_cli)
              if getattr(from_cli, f.name) != getattr(from_api, f.name)} - exempt
    assert differ == set(), {f: (getattr(from_cli, f), getattr(from_api, f)) for f in differ}
    if name != "run":
        assert from_cli.workers == 1 and from_api.workers == checks.usable_cores()


def test_options_are_frozen_hashable_and_travel_whole_without_a_client():
    """A worker keys its FMUs by (scenario, options): the object must hash and pickle; a
    distributed.Client does not travel (its address does)."""
    import pickle

    class Client:  # stands for distributed.Client (matched by its module)
        class scheduler:
            address = "tcp://127.0.0.1:8786"

    Client.__module__ = "distributed.client"
    made = options.CampaignOptions(scenario=MC, runs=3, scheduler=Client(), sets={"vehicle.h0": 91000.0})
    with pytest.raises(dataclasses.FrozenInstanceError):
        made.runs = 4
    hash(made)
    sent = pickle.loads(pickle.dumps(made))
    assert sent.scheduler == "tcp://127.0.0.1:8786" and sent.overrides == {"vehicle.h0": 91000.0}
    assert dataclasses.replace(sent, scheduler=None) == dataclasses.replace(made, scheduler=None)
