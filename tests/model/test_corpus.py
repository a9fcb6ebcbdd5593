"""The input-validation catalogue: every malformed file of tests/data/corpus gives one clear line.

tests/data/corpus/index.json lists each case: the file, its kind (scenario or wiring) and
fragments of the expected error line (entry, message, fix). Each case goes through `run`,
`check` and `validate`; each must exit with status 2 and print exactly one line on stderr,
`error: FILE: ENTRY: CAUSE; FIX`, naming the file, and no traceback. A wiring case is run
through a scenario written beside the test that points at the corpus wiring file. The crafted
FMU archives the wiring cases name (tests/data/corpus/fmus/, not tracked) are written by
tests/data/corpus/make_archives.py before the module runs.
"""

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from aotv_cosim.cli import main
from tests.helpers import ROOT, cli, run_process, write_json
from tests.model.archives import CORPUS

pytestmark = pytest.mark.usefixtures("crafted_archives")  # the wiring cases name them

CASES = json.loads((CORPUS / "index.json").read_text())["cases"]


def _scenario_for(case, tmp_path):
    """The scenario file to run for a case: the case itself, or one using the case's wiring."""
    if case["kind"] == "scenario":
        return CORPUS / case["file"]
    return write_json(tmp_path / "uses_wiring.json",
                      {"system": str(CORPUS / case["file"]), "stop": 1.0, "step": 0.1})


def _commands(case, tmp_path):
    scenario = _scenario_for(case, tmp_path)
    return {"run": ["run", scenario, "--out", tmp_path / "run", "--no-plots"],
            "check": ["check", scenario, "--out", tmp_path / "check"],
            "validate": ["validate", CORPUS / case["file"]]}


def assert_one_clear_line(case, code, stderr, stdout=""):
    assert code == 2, (code, stdout, stderr)
    assert "Traceback" not in stderr + stdout
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, lines
    line = lines[0]
    assert line.startswith(f"error: {CORPUS / case['file']}: {case['entry']}"), line
    cause, _, fix = line.partition("; ")
    assert case["message"] in cause, line
    assert fix and case["fix"] in fix, line


def test_the_corpus_is_complete():
    """At least 30 cases, every file listed exists, and every corpus file is a case."""
    assert len(CASES) >= 30
    listed = {c["file"] for c in CASES}
    assert listed == {p.name for p in CORPUS.glob("*.json")} - {"index.json"}
    assert len(listed) == len(CASES)


@pytest.mark.integration
@pytest.mark.parametrize("command", ["run", "check", "validate"])
@pytest.mark.parametrize("case", CASES, ids=[c["file"][:-5] for c in CASES])
def test_bad_input_gives_exit_2_and_one_line(case, command, tmp_path):
    args = _commands(case, tmp_path)[command]
    result = cli(*args)
    assert_one_clear_line(case, result.exit_code, result.stderr, result.stdout)
    assert not (tmp_path / "run" / "summary.json").exists()


@pytest.mark.integration
def test_code_in_a_scenario_is_never_run(tmp_path):
    """A string that would run a shell command if evaluated is only ever a wrong-type value."""
    marker = Path("/tmp/aotv_pwned")
    marker.unlink(missing_ok=True)
    case = next(c for c in CASES if c["file"] == "scenario_override_code_is_not_evaluated.json")
    for command in ("run", "check", "validate"):
        CliRunner().invoke(main, [str(a) for a in _commands(case, tmp_path)[command]])
    assert not marker.exists()


@pytest.mark.integration
@pytest.mark.parametrize("name", ["scenario_syntax_double_comma.json", "wiring_fmu_not_a_zip.json"])
def test_a_real_process_prints_one_line(name, tmp_path):
    """Outside CliRunner too: a subprocess prints one line and exits 2; --debug adds the traceback."""
    case = next(c for c in CASES if c["file"] == name)
    done = run_process("validate", CORPUS / name, timeout=120)
    assert_one_clear_line(case, done.returncode, done.stderr, done.stdout)
    debug = run_process("--debug", "validate", CORPUS / name, timeout=120)
    assert debug.returncode != 0 and "Traceback" in debug.stderr


def _properties(node, where="#"):
    """(location, schema) of every property declared anywhere inside a schema."""
    if isinstance(node, dict):
        for name, sub in node.get("properties", {}).items():
            yield f"{where}/properties/{name}", sub
        for key, sub in node.items():
            yield from _properties(sub, f"{where}/{key}")
    elif isinstance(node, list):
        for k, sub in enumerate(node):
            yield from _properties(sub, f"{where}/{k}")


@pytest.mark.parametrize("kind", ["scenario", "wiring"])
def test_schemas_serve_editors(kind):
    """Valid 2020-12 schemas with $id, title and a description on every property; every shipped
    file names a schema in "$schema", wiring files those of systems/ and scenarios the others."""
    import jsonschema

    from aotv_cosim.model.documents import schema

    doc = schema(kind)
    jsonschema.Draft202012Validator.check_schema(doc)
    assert doc["$id"].endswith(f"{kind}.schema.json") and doc["title"] and doc["description"]
    undocumented = [where for where, sub in _properties(doc) if "description" not in sub]
    assert not undocumented
    target = ROOT / "aotv_cosim" / "schemas" / f"{kind}.schema.json"
    shipped = [p for p in sorted((ROOT / "scenarios").rglob("*.json"))
               if (p.parent / json.loads(p.read_text())["$schema"]).resolve() == target]
    assert len(shipped) >= 3
    if kind == "wiring":
        assert all(p.parent.name == "systems" for p in shipped), shipped
    else:  # scenarios/ and its scenario sets (benchmark_seed000/), never a wiring folder
        assert all(p.parent.name != "systems" for p in shipped), shipped


def test_every_case_is_in_the_documented_catalogue():
    catalogue = (ROOT / "docs" / "reliability.md").read_text()
    assert not [c["file"] for c in CASES if f"`{c['file']}`" not in catalogue]
