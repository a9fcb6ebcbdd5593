"""The attack corpus (issue 34), runnable by anyone: every case of `tests/attacks/corpus.py` run as
`tests/attacks/harness.py` says, and the corpus's table in docs/reliability.md kept in step with it.

Cases that need this package's FMUs are marked integration (the session's `built_fmus` fixture
builds them first); cases that wait for seconds (signals sent to a process of its own, a time limit
run out, an unroutable address) are marked slow: `python -m pytest -m slow tests/attacks` runs them.
"""

import pytest

from tests.attacks.corpus import CASES, table
from tests.attacks.harness import run_case
from tests.helpers import ROOT


def _marks(case):
    marks = [pytest.mark.timeout(case.limit + 60, method="thread")]
    if case.fmus:
        marks.append(pytest.mark.integration)
    if case.slow:
        marks.append(pytest.mark.slow)
    return marks


@pytest.mark.parametrize("case", [pytest.param(c, id=f"{c.face}:{c.name}", marks=_marks(c)) for c in CASES])
def test_attack(case, tmp_path, monkeypatch, request):
    if case.name.startswith("set-typed") or "crafted" in case.name:
        request.getfixturevalue("crafted_archives")
    run_case(case, tmp_path, monkeypatch)


def test_the_corpus_is_large_and_each_case_is_named_once():
    assert len(CASES) >= 150
    names = [(c.face, c.name) for c in CASES]
    assert len(set(names)) == len(names)


def test_the_documented_table_is_the_corpus():
    assert table() in (ROOT / "docs" / "reliability.md").read_text()
