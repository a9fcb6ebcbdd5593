"""Fuzzing the loaders with hypothesis: random text, random JSON documents and mutations of the
seed-000 scenario and wiring files either load or raise the project's own error (an AotvError
subclass), never anything else. The default run keeps each property to a few dozen examples; the
`slow` marker runs the same properties with thousands (`python -m pytest -m slow tests/test_fuzz.py`).
"""

import contextlib
import copy
import json
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from aotv_cosim.model.documents import load_document
from aotv_cosim.errors import AotvError
from aotv_cosim.simulation.loading import load_scenario
from aotv_cosim.simulation.loading import load_system
from aotv_cosim.fmu.build import built_fmu
from tests.helpers import NOMINAL, WIRING

SCENARIO = json.loads(NOMINAL.read_text())
SCENARIO["system"] = str(WIRING)
WIRING_DOC = json.loads(WIRING.read_text())
FOLDER = Path(tempfile.mkdtemp(prefix="aotv_fuzz_"))

BUDGETS = [pytest.param(40, id="fast"), pytest.param(2000, id="long", marks=pytest.mark.slow)]

numbers = st.one_of(st.integers(), st.integers(min_value=-10**400, max_value=10**400),
                    st.floats(allow_nan=False, allow_infinity=False),
                    st.sampled_from([0, -1, 0.0, -0.0, 1e-320, 1e308, -1e308, 2**31, 2**63]))
names = st.one_of(st.text(max_size=12), st.sampled_from(
    ["vehicle", "atmosphere", "guidance", "actuator", "vehicle.h", "vehicle.h0", "guidance.u",
     "a.b -> c.d", "vehicle.h -> atmosphere.h", "x.y->z.w -> v.u", "end", "event", "min", "..", "/"]))
scalars = st.one_of(st.none(), st.booleans(), numbers, names)
json_values = st.recursive(scalars, lambda inner: st.lists(inner, max_size=4)
                           | st.dictionaries(names, inner, max_size=4), max_leaves=12)


def _loads_or_own_error(load, text):
    """Write `text` to a file and load it; anything but success or an AotvError fails the test."""
    path = FOLDER / "doc.json"
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    with contextlib.suppress(AotvError):
        load(path)


def _paths(doc, prefix=()):
    """Every (path) to a value inside a JSON document, the document itself included."""
    yield prefix
    items = doc.items() if isinstance(doc, dict) else enumerate(doc) if isinstance(doc, list) else ()
    for key, value in items:
        yield from _paths(value, (*prefix, key))


@st.composite
def mutations(draw, original):
    """The original document with 1-4 random edits: replace, delete or add a value anywhere."""
    doc = copy.deepcopy(original)
    for _ in range(draw(st.integers(1, 4))):
        paths = [p for p in _paths(doc) if p]
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        parent = doc
        for key in path[:-1]:
            parent = parent[key]
        action = draw(st.sampled_from(["replace", "delete", "add"]))
        if action == "replace":
            parent[path[-1]] = draw(json_values)
        elif action == "delete":
            del parent[path[-1]]
        elif isinstance(parent, dict):
            parent[draw(names)] = draw(json_values)
        else:
            parent.insert(path[-1], draw(json_values))
    return doc


def _fuzz(strategy, check, budget):
    @settings(max_examples=budget, deadline=None, database=None,
              suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
    @given(strategy)
    def run(value):
        check(value)

    run()


def load_wiring(path):
    return load_system(path, fmus=built_fmu)


LOADERS = {"scenario": load_scenario, "wiring": load_wiring,
           "scenario document": lambda p: load_document(p, "scenario"),
           "wiring document": lambda p: load_document(p, "wiring")}


@pytest.mark.parametrize("budget", BUDGETS)
@pytest.mark.parametrize("loader", sorted(LOADERS))
def test_random_text(loader, budget):
    _fuzz(st.text(max_size=200), lambda text: _loads_or_own_error(LOADERS[loader], text), budget)


@pytest.mark.parametrize("budget", BUDGETS)
@pytest.mark.parametrize("loader", sorted(LOADERS))
def test_random_json(loader, budget):
    _fuzz(json_values, lambda doc: _loads_or_own_error(LOADERS[loader], json.dumps(doc)), budget)


@pytest.mark.integration
@pytest.mark.parametrize("budget", BUDGETS)
def test_mutated_scenario(budget):
    _fuzz(mutations(SCENARIO), lambda doc: _loads_or_own_error(load_scenario, json.dumps(doc)), budget)


@pytest.mark.integration
@pytest.mark.parametrize("budget", BUDGETS)
def test_mutated_wiring(budget):
    _fuzz(mutations(WIRING_DOC), lambda doc: _loads_or_own_error(load_wiring, json.dumps(doc)), budget)


@pytest.mark.integration
@pytest.mark.parametrize("budget", BUDGETS)
def test_scenario_with_mutated_wiring(budget):
    """A valid scenario over a mutated wiring file: errors from either file are the project's."""
    scenario = FOLDER / "uses_wiring.json"
    scenario.write_text(json.dumps(dict(SCENARIO, system="wiring.json")))

    def check(doc):
        (FOLDER / "wiring.json").write_text(json.dumps(doc))
        with contextlib.suppress(AotvError):
            load_scenario(scenario)

    _fuzz(mutations(WIRING_DOC), check, budget)


paths = st.one_of(st.text(max_size=40), st.text(alphabet="ab./\\\0~:", max_size=40),
                  st.integers(250, 5000).map(lambda n: "x" * n), st.sampled_from(
                      ["/dev/zero", "/dev/null", "/", "..", "/proc/self/fd/0", "\0", "a\0.json", "x.fmu"]))


@pytest.mark.integration
@pytest.mark.parametrize("budget", BUDGETS)
def test_random_paths(budget):
    """Any string as the scenario's system or a component's FMU path (NUL bytes, over-long names,
    devices, folders) is loaded or refused with the project's error, never another exception."""

    def check(text):
        wiring = dict(WIRING_DOC, components=dict(WIRING_DOC["components"],
                                                  atmosphere={"fmu": text + ".fmu"}))
        _loads_or_own_error(load_wiring, json.dumps(wiring))
        _loads_or_own_error(load_scenario, json.dumps(dict(SCENARIO, system=text)))

    _fuzz(paths, check, budget)
