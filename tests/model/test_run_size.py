"""Run size: a warning for runs writing millions of rows, a refusal for a step
below the resolution of the time values."""

import pytest

from tests.helpers import error_lines, invoke, write_json

pytestmark = pytest.mark.integration


def test_step_below_time_resolution_is_refused(tmp_path, scenario_doc):
    scenario_doc.update(start=1e17, stop=1e17 + 300.0, step=1.0)
    scenario_doc.pop("expectations", None)
    code, text = invoke("validate", write_json(tmp_path / "s.json", scenario_doc))
    lines = error_lines(text)
    assert code == 2 and len(lines) == 1, text
    assert "step: step 1 s is below the resolution of the time values" in lines[0]
    assert "multiples of 16 s" in lines[0] and "; give a step of at least 16000 s" in lines[0]


def test_millions_of_rows_warn_at_validation(tmp_path, scenario_doc):
    scenario_doc.update(stop=1e6, step=0.001)
    scenario_doc.pop("expectations", None)
    code, text = invoke("validate", write_json(tmp_path / "s.json", scenario_doc))
    assert code == 0, text
    assert "warning:" in text and "will write 1e+09 rows of timeseries.csv" in text, text
    scenario_doc.update(record_every=1000)
    code, text = invoke("validate", write_json(tmp_path / "s.json", scenario_doc))
    assert code == 0 and "warning:" not in text, text


def test_ordinary_scenario_has_no_warning(tmp_path, scenario_doc):
    code, text = invoke("validate", write_json(tmp_path / "s.json", scenario_doc))
    assert code == 0 and "warning:" not in text, text
