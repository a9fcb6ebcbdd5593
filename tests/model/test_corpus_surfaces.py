"""Bad input at the command-line surfaces that are not scenario or wiring files: typed values given
by --set, a user's FMU source (build-fmus, a wiring's "fmu": "X.py", describe), benchmark --law
files, sweep grids and corridor brackets. Each ends in exit 2 and one line
`error: FILE: ENTRY: CAUSE; FIX`, with no traceback, before any run when the input alone shows
the problem. The typed-value cases use the corpus's crafted FMU tests/data/corpus/fmus/typed.fmu
(an Integer n, a Boolean flag, an Enumeration mode of items Hold=1 and Ramp=2, a String text).
"""

import json
import os

import pytest
from click.testing import CliRunner

from aotv_cosim.options.checks import MAX_POINTS, parse_grid
from aotv_cosim.cli import main
from tests.helpers import SCENARIOS, cli, write_json
from tests.model.archives import CORPUS

pytestmark = pytest.mark.usefixtures("crafted_archives")  # the wiring cases name them

PASS = SCENARIOS / "benchmark_seed000" / "time_linear.json"
"""A shipped scenario that declares an outcome (sweeps, corridors) and a benchmark set member."""


def one_line(args, file, entry, message, fix):
    """Run the CLI; assert exit 2 and the one line naming file, entry, cause and fix."""
    result = cli(*args)
    assert result.exit_code == 2, (result.exit_code, result.output)
    assert "Traceback" not in result.output
    line, = result.stderr.strip().splitlines()
    assert line.startswith(f"error: {file}: {entry}"), line
    cause, _, given_fix = line.partition("; ")
    assert message in cause and fix in given_fix, line
    return line


@pytest.fixture
def typed_scenario(tmp_path):
    """A valid scenario of one typed.fmu component (its inputs given values)."""
    write_json(tmp_path / "w.json", {"components": {"t": {"fmu": str(CORPUS / "fmus" / "typed.fmu"),
                                                          "parameters": {"u": 0.0, "m": 0}}}, "connections": []})
    return write_json(tmp_path / "s.json", {"system": "w.json", "stop": 1.0, "step": 0.5})


SETS = [("t.n=2147483648", "t.n", "n is a 32-bit Integer, got 2147483648", "between -2147483648 and 2147483647"),
        ("t.n=-2147483649", "t.n", "got -2147483649", "between -2147483648"),
        ("t.n=nan", "t.n", "n is Integer, got 'nan'", "give an Integer value"),
        ("t.n=inf", "t.n", "n is Integer, got 'inf'", "give an Integer value"),
        ("t.n=1.5", "t.n", "n is Integer, got 1.5", "give an Integer value"),
        ("t.n=1e400", "t.n", "n is Integer, got '1e400'", "give an Integer value"),
        ("t.mode=Sideways", "t.mode", "mode is an Enumeration, got 'Sideways'", "1 ('Hold'), 2 ('Ramp')"),
        ("t.mode=0", "t.mode", "mode is an Enumeration, got 0", "1 ('Hold'), 2 ('Ramp')"),
        ("t.mode=true", "t.mode", "mode is an Enumeration, got True", "1 ('Hold'), 2 ('Ramp')"),
        ("t.flag=yes", "t.flag", "flag is Boolean, got 'yes'", "give a Boolean value"),
        ("t.flag=TRUE", "t.flag", "flag is Boolean, got 'TRUE'", "give a Boolean value"),
        ("t.flag=True", "t.flag", "flag is Boolean, got 'True'", "give a Boolean value"),
        ("t.flag=1", "t.flag", "flag is Boolean, got 1", "give a Boolean value"),
        ("t.text=caf\udce9", "t.text", "text is a String, got 'caf\\udce9' (a NUL character or text that is not UTF-8)",
         "give UTF-8 text"),
        ('t.text="a\\u0000b"', "t.text", "got 'a\\x00b'", "without NUL characters"),
        ("t.text=" + "x" * 100000, "t.text", "", ""),  # accepted: FMI sets no length limit
        ("t.n=" + "x" * 100000, "t.n", "'xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx'... (100000 characters)",
         "give an Integer")]


@pytest.mark.parametrize("given, entry, message, fix", SETS, ids=[s[0][:24] for s in SETS])
def test_a_bad_typed_value_given_by_set_is_one_line(given, entry, message, fix, typed_scenario, tmp_path):
    """A value given on the command line (a byte that is not UTF-8 arrives as a lone surrogate)."""
    args = ["run", typed_scenario, "--set", given, "--out", tmp_path / "o", "--no-plots"]
    if not message:  # a valid value: refused neither by the loader nor for its length
        from aotv_cosim.model.documents import parse_sets
        from aotv_cosim.simulation.loading import load_scenario

        scenario = load_scenario(typed_scenario, parse_sets([given]))
        assert scenario.system.components["t"].parameters["text"] == "x" * 100000
        return
    one_line(args, f"{typed_scenario} (with --set)", f"parameters.{entry}", message, fix)
    assert not (tmp_path / "o").exists()


def test_enumeration_items_and_booleans_are_accepted_as_documented(typed_scenario):
    """An Enumeration by item name (exact case) or integer; a Boolean only as JSON true/false."""
    from aotv_cosim.model.documents import parse_sets
    from aotv_cosim.simulation.loading import load_scenario

    parameters = load_scenario(typed_scenario, parse_sets(["t.mode=Ramp",
                                                           "t.flag=true"])).system.components["t"].parameters
    assert parameters["mode"] == 2 and parameters["flag"] is True
    assert load_scenario(typed_scenario, {"t.mode": 1}).system.components["t"].parameters["mode"] == 1


# --- a user's FMU source -------------------------------------------------------------------------

SOURCES = {
    "Syntax.py": (b"def broken(:\n    pass\n", "line 1", "importing it raised SyntaxError: invalid syntax"),
    "Imports.py": (b"import no_such_module_for_aotv\n", "line 1", "ModuleNotFoundError: No module named"),
    "NoStep.py": (b"from aotv_cosim.laws import AotvSlave\n\n\nclass NoStep(AotvSlave):\n    pass\n",
                  "(top level)", "defines no concrete FMU class"),
    "Binary.py": (bytes(range(256)), "line 2", "SyntaxError: byte 0x80 is not valid utf-8"),
    "Latin1.py": (b"# caf\xe9\nx = 1\n", "line 1", "SyntaxError: byte 0xe9 is not valid utf-8"),  # PEP 263
    "Exits.py": (b"import sys\nsys.exit(0)\n", "line 2", "importing it called sys.exit(0)"),
}


@pytest.mark.integration
@pytest.mark.parametrize("name", sorted(SOURCES))
def test_a_bad_fmu_source_is_one_line_from_build_fmus_a_wiring_and_describe(name, tmp_path):
    """build-fmus, a wiring naming the source and describe: the source's file, line and cause, and
    no progress line before it (the source is checked before a build starts)."""
    text, entry, message = SOURCES[name]
    source = tmp_path / "laws" / name
    source.parent.mkdir()
    source.write_bytes(text)
    one_line(["build-fmus", source, "--out", tmp_path / "built"], source, entry, message, "")
    write_json(tmp_path / "w.json", {"components": {"g": {"fmu": f"laws/{name}"}}, "connections": []})
    one_line(["validate", tmp_path / "w.json"], source, entry, message, "")
    one_line(["describe", source], source, entry, message, "")


@pytest.mark.integration
def test_a_class_declaring_no_variable_is_input_not_a_build_failure(tmp_path):
    """Found only once pythonfmu has built it (fmpy validate), so after the build's progress lines:
    the last line names the source, and the status is 2 (bad input), not 1 (a failed build)."""
    source = tmp_path / "Quiet.py"
    source.write_text("from aotv_cosim.laws import AotvSlave\n\n\nclass Quiet(AotvSlave):\n"
                      "    def do_step(self, t, dt):\n        return True\n")
    result = CliRunner().invoke(main, ["build-fmus", str(source), "--out", str(tmp_path / "built")])
    assert result.exit_code == 2 and "Traceback" not in result.output
    assert result.stderr.strip().splitlines()[-1].startswith(
        f"error: {source}: modelDescription.xml: fmpy validate: ERROR")


@pytest.mark.integration
def test_a_class_named_apart_from_its_file_builds(tmp_path):
    """The FMU is named by its class (modelIdentifier, its binary), the file by the user."""
    from fmpy import read_model_description

    source = tmp_path / "my_law.py"
    source.write_text("from aotv_cosim.laws import AotvSlave\n\n\nclass Pull(AotvSlave):\n"
                      "    def __init__(self, **kwargs):\n        super().__init__(**kwargs)\n"
                      "        self.parameter('u0', 0.5, 'm/s2', 'Lift command')\n"
                      "        self.output('u', 'm/s2', 'Lift command', lambda: self.u0)\n\n"
                      "    def do_step(self, t, dt):\n        return True\n")
    result = CliRunner().invoke(main, ["build-fmus", str(source), "--out", str(tmp_path / "built")])
    assert result.exit_code == 0, result.output
    assert read_model_description(str(tmp_path / "built" / "my_law.fmu")).coSimulation.modelIdentifier == "Pull"


def test_a_missing_source_is_one_line(tmp_path):
    missing = tmp_path / "Missing.py"
    result = CliRunner().invoke(main, ["build-fmus", str(missing)])
    assert result.exit_code == 2 and result.stderr.strip().splitlines() == [
        f"error: {missing}: file not found; give the path of a Python file defining one FMU class "
        "(see docs/writing-a-guidance-law.md)"]
    write_json(tmp_path / "w.json", {"components": {"g": {"fmu": "Missing.py"}}, "connections": []})
    one_line(["validate", tmp_path / "w.json"], tmp_path / "w.json", "components.g.fmu",
             "FMU source file not found", "correct the path")


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads a chmod 000 folder: nothing is unreadable to test")
def test_a_source_in_an_unreadable_folder_is_one_line(tmp_path):
    folder = tmp_path / "locked"
    folder.mkdir()
    (folder / "Law.py").write_text("x = 1\n")
    folder.chmod(0)
    try:
        result = CliRunner().invoke(main, ["build-fmus", str(folder / "Law.py"), "--out", str(tmp_path / "b")])
    finally:
        folder.chmod(0o755)
    assert result.exit_code == 2 and len(result.stderr.strip().splitlines()) == 1, result.output


# --- benchmark --law -----------------------------------------------------------------------------

def _wiring_law(path, **change):
    doc = json.loads((SCENARIOS / "systems" / "aotv_time_linear.json").read_text())
    doc["components"]["guidance"].update(change)
    path.parent.mkdir(parents=True, exist_ok=True)
    return write_json(path, doc)


@pytest.mark.integration
def test_bad_law_files_are_one_line_before_any_run(tmp_path):
    out = tmp_path / "o"
    bench = ["benchmark", PASS, "--runs", "2", "--out", out]
    result = CliRunner().invoke(main, [str(a) for a in [*bench, "--law", tmp_path / "missing.json"]])
    assert result.exit_code == 2 and len(result.stderr.strip().splitlines()) == 1
    assert f"error: {tmp_path / 'missing.json'}: --law: file not found; give the path of an existing law" \
        in result.stderr
    unknown = _wiring_law(tmp_path / "unknown.json", fmu="NoSuchLaw")
    one_line([*bench, "--law", unknown], unknown, "components.guidance.fmu", "no FMU named 'NoSuchLaw'",
             "give a path to a .fmu file")
    first, second = _wiring_law(tmp_path / "a" / "mine.json"), _wiring_law(tmp_path / "b" / "mine.json")
    one_line([*bench, "--law", first, "--law", second], second, "--law",
             "a law named 'mine' is already given by another --law file", "rename the law file")
    clash = _wiring_law(tmp_path / "time_linear.json")
    one_line([*bench, "--law", clash], clash, "--law", "a law named 'time_linear' is already in the set", "rename")
    other = json.loads(PASS.read_text())
    other["system"] = str((PASS.parent / other["system"]).resolve())
    other.pop("dispersion_set")
    other["dispersions"] = {"vehicle.gamma0": {"distribution": "uniform", "low": -0.021, "high": -0.019}}
    scenario = write_json(tmp_path / "scenario_law.json", other)
    one_line([*bench, "--law", scenario], scenario, "dispersions", "its dispersions differ from those of",
             "use the dispersion_set")
    assert not list(out.rglob("rows*"))  # refused before any law is flown


# --- sweep grids ---------------------------------------------------------------------------------

GRIDS = [(["vehicle.gamma0=-0.03:-0.01:0"], "asks for 0 points", f"give N from 1 to {MAX_POINTS}"),
         (["vehicle.gamma0=-0.03:-0.01:10000000"], "asks for 10000000 points", "give N from 1"),
         (["vehicle.gamma0=-0.03:-0.01:1000", "vehicle.v0=8000:8400:1000"], "the grids make 1000000 points",
          f"give at most {MAX_POINTS} points"),
         (["vehicle.gamma0=-0.03:-0.01:2.5"], "cannot read the grid", "COMP.VAR=LOW:HIGH:N"),
         (["vehicle.gamma0=steep,shallow"], "cannot read the grid", "COMP.VAR=A,B,C"),
         (["vehicle.gamma0=-0.03:inf:3"], "has a value that is not finite", "COMP.VAR"),
         (["vehicle.gamma0=-0.02", "vehicle.gamma0=-0.03"], "vehicle.gamma0 is given by several grids",
          "give each parameter one --grid"),
         (["vehicle.gamma00=-0.02,-0.03"], "vehicle.gamma00 is not a Real parameter of the system", "describe"),
         (["engine.thrust=1,2"], "engine.thrust is not a Real parameter of the system", "describe")]


@pytest.mark.integration
@pytest.mark.parametrize("grids, message, fix", GRIDS, ids=[g[1][:30] for g in GRIDS])
def test_a_bad_grid_is_one_line_before_any_run(grids, message, fix, tmp_path):
    args = ["sweep", PASS, "--out", tmp_path / "o"] + [a for g in grids for a in ("--grid", g)]
    one_line(args, PASS, "--grid", message, fix)
    assert not (tmp_path / "o" / "sweep.csv").exists()


def test_a_reversed_range_is_flown_in_descending_order():
    name, values = parse_grid("vehicle.gamma0=-0.01:-0.03:3")
    assert name == "vehicle.gamma0" and values == pytest.approx([-0.01, -0.02, -0.03], abs=1e-15)


# --- corridor brackets ---------------------------------------------------------------------------

BRACKETS = [(("-0.002", "-0.08"), "--bracket", "the bracket (-0.002, -0.08) rad is not a finite range", "STEEP < "
                                                                                                        "SHALLOW"),
            (("-0.02", "-0.02"), "--bracket", "the bracket (-0.02, -0.02) rad", "STEEP < SHALLOW"),
            (("nan", "-0.02"), "--bracket", "the bracket (nan, -0.02) rad", "STEEP < SHALLOW"),
            (("-inf", "-0.02"), "--bracket", "the bracket (-inf, -0.02) rad", "STEEP < SHALLOW")]


@pytest.mark.parametrize("bracket, entry, message, fix", BRACKETS, ids=[" ".join(b[0]) for b in BRACKETS])
def test_a_bracket_that_is_no_range_is_one_line_before_any_run(bracket, entry, message, fix, tmp_path):
    one_line(["corridor", PASS, "--lift-to-drag", "5", "--bracket", *bracket, "--out", tmp_path / "o"],
             PASS, entry, message, fix)
    assert not (tmp_path / "o" / "lift_up.json").exists()  # refused before the corridor's scenarios are written


@pytest.mark.parametrize("option", [("--tolerance", "inf"), ("--lift-to-drag", "nan"), ("--tolerance", "0")])
def test_a_corridor_tolerance_or_lift_to_drag_that_is_not_finite_and_positive_is_one_line(option, tmp_path):
    args = ["corridor", PASS, "--lift-to-drag", "5", *option, "--out", tmp_path / "o"]
    one_line(args, PASS, option[0], "is not a finite number above 0", "give a finite number above 0")


@pytest.mark.integration
def test_a_bracket_on_one_side_of_the_edge_is_one_line(tmp_path):
    """Both bounds steeper than the steep bound: two runs show it does not bracket."""
    one_line(["corridor", PASS, "--lift-to-drag", "5", "--bracket", "-0.08", "-0.07", "--out", tmp_path / "o"],
             tmp_path / "o" / "lift_up.json", "--bracket", "lift_up: the apogee error does not cross +0 m",
             "give --bracket STEEP SHALLOW around the edge")


def test_an_fmu_whose_binary_cannot_be_loaded_is_one_line(typed_scenario, tmp_path, monkeypatch):
    """typed.fmu passes validate (its modelDescription is sound) but its binary is text: the run
    names the FMU and the loader's reason (was exit 3 and FMPy's 'Failed to load shared library')."""
    monkeypatch.chdir(tmp_path)  # FMPy stays in the binary's folder when loading fails: undone after the test
    one_line(["run", typed_scenario, "--out", tmp_path / "o", "--no-plots"], CORPUS / "fmus" / "typed.fmu",
             "component t", "typed.fmu: its binary cannot be loaded: file too short", "give an FMU whose binary")
