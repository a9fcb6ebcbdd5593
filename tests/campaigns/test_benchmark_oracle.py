"""Every law of a benchmark scored against its set's oracle (issue 36, item 2): the oracle is read
from the typed scenario settings, flown once like a law (its rows stored and reused), joined to
every law's rows by run index; each law's dv penalty (its dv minus the oracle's, over the runs both
captured) is scored (p50, p99.865) beside the oracle's own capture rate; a set without an oracle
is unchanged; two oracles, or a --law that declares itself one, are refused in one line."""

import json
import math
from types import SimpleNamespace

import numpy as np
import pyarrow.parquet as pq
import pytest
from click.testing import CliRunner

from aotv_cosim.campaigns import benchmark, benchmark_report, oracle_score
from aotv_cosim.campaigns.benchmark import METRICS, run_benchmark, score, score_columns
from aotv_cosim.cli import main
from aotv_cosim.errors import InputError
from aotv_cosim.options import BenchmarkOptions
from tests.helpers import SCENARIOS, write_json

AFE = SCENARIOS / "benchmark_aerocapture" / "afe"


@pytest.fixture(autouse=True)
def fresh_store(tmp_path, monkeypatch):
    """Each test starts with no stored campaign rows (they would be reused, not flown)."""
    monkeypatch.setattr(benchmark, "stored_rows_dir", lambda: tmp_path / "stored")


def _row(run, outcome, dv):
    return {"run": run, "status": "completed" if outcome != "failed" else "failed", "outcome": outcome,
            "outcome.dv_total": dv}


def test_rows_are_joined_by_run_index_and_only_runs_both_captured_have_a_penalty():
    oracle = [_row(0, "captured", 91.0), _row(1, "captured", 92.0), _row(2, "skip_out", 95.0),
              _row(3, "captured", 93.0)]
    law = [_row(3, "captured", 92.5), _row(1, "skip_out", 400.0), _row(0, "captured", 101.0),
           _row(2, "captured", 99.0)]  # rows in another order than the oracle's: joined by "run"
    joined = oracle_score.joined({"oracle": oracle, "law": law}, "oracle")
    dv = {r["run"]: r[oracle_score.ORACLE_DV] for r in joined["law"]}
    penalty = {r["run"]: r[oracle_score.PENALTY] for r in joined["law"]}
    assert dv == {3: 93.0, 1: 92.0, 0: 91.0, 2: 95.0}  # the oracle's dv of the same run, as it is
    assert penalty[0] == 101.0 - 91.0 > 0  # the law's dv minus the oracle's
    assert penalty[3] == 92.5 - 93.0 < 0  # a run where the law spent less than the oracle's pass
    assert math.isnan(penalty[1])  # the law did not capture it: no penalty
    assert math.isnan(penalty[2])  # the oracle did not capture it: nothing to be scored against
    assert all(math.isnan(r[oracle_score.PENALTY]) for r in joined["oracle"])  # the oracle has none
    assert [r[oracle_score.ORACLE_DV] for r in joined["oracle"]] == [91.0, 92.0, 95.0, 93.0]
    assert [{k: r[k] for k in law[0]} for r in joined["law"]] == law  # the law's own columns untouched


def test_the_penalty_is_scored_after_the_correction_dv_over_the_runs_both_captured():
    metrics = oracle_score.with_penalty(METRICS)
    names = [m[0] for m in metrics]
    assert names.index(oracle_score.PENALTY) == names.index("outcome.dv_total") + 1
    rng = np.random.default_rng(3)
    oracle = [_row(k, "captured" if k % 7 else "undershoot", 90.0 + rng.random()) for k in range(50)]
    law = [_row(k, "captured" if k % 5 else "skip_out", 100.0 + 10.0 * rng.random()) for k in range(50)]
    joined = oracle_score.joined({"oracle": oracle, "law": law}, "oracle")
    both = [k for k in range(50) if k % 7 and k % 5]
    expected = np.array([law[k]["outcome.dv_total"] - oracle[k]["outcome.dv_total"] for k in both])
    card = score("law", joined["law"], None, (oracle_score.METRIC,))
    assert card["dv_penalty_p50"] == np.percentile(expected, 50.0)
    assert card["dv_penalty_p99.865"] == np.percentile(expected, 99.865)
    assert score("oracle", joined["oracle"], None, (oracle_score.METRIC,))["dv_penalty_p50"] is None
    columns = dict(score_columns(metrics, roles=True))
    assert list(columns)[:2] == ["law", "role"] and columns["dv_penalty_p99.865"] == "m/s"
    assert "role" not in dict(score_columns()) and "dv_penalty_p50" not in dict(score_columns())


def test_a_set_has_at_most_one_oracle_and_its_laws_template_is_not_it():
    def scenario(oracle):
        return SimpleNamespace(oracle=oracle)

    from pathlib import Path

    laws = [(Path("a_oracle.json"), scenario(True)), (Path("b.json"), scenario(False))]
    assert oracle_score.of_set(laws) == "a_oracle" and oracle_score.first_law(laws) == laws[1]
    assert oracle_score.of_set(laws[1:]) is None and oracle_score.first_law(laws[:1]) == laws[0]
    with pytest.raises(InputError, match=r"c\.json: montecarlo\.oracle: a second oracle: a_oracle\.json is the "
                                         r"set's oracle already; keep \"oracle\": true in one scenario"):
        oracle_score.of_set([*laws, (Path("c.json"), scenario(True))])


def test_the_figure_draws_the_penalty_after_the_dv_and_the_total_heating_where_the_runs_give_it(tmp_path, drawn):
    base = [{**_row(k, "captured", 100.0 + k), "outcome.apogee_error": 10.0 * k,
             **{c: 1.0 + k for c, _, _ in benchmark_report.PANELS[2:]}} for k in range(20)]
    convective = [{**r, "outcome.peak_heat_rate_total": math.nan, "outcome.heat_load_total": math.nan,
                   "outcome.peak_heat_rate": 1.0, "outcome.heat_load": 2.0} for r in base]
    assert [p[1] for p in benchmark_report.panels_of({"a": base})][2:4] == ["peak total heat rate", "total heat load"]
    assert [p[1] for p in benchmark_report.panels_of({"a": convective})][2:4] == ["peak heat rate", "heat load"]
    oracle = [{**r, "outcome.dv_total": 90.0 + 0.01 * r["run"]} for r in base]
    law = [{**r, "outcome": "skip_out"} if r["run"] < 4 else r for r in base]
    never = [{**r, "outcome": "skip_out"} for r in base]
    rows = oracle_score.joined({"oracle": oracle, "mine": law, "never": never}, "oracle")
    panels = benchmark_report.panels_of(rows, "oracle")
    assert [p[0] for p in panels][1:3] == ["outcome.dv_total", oracle_score.PENALTY]
    benchmark_report.plots(tmp_path, rows, 10e3, panels, "oracle")
    outcome, _, _, penalty, heat, *_ = drawn[(tmp_path / "benchmark.png").resolve()].panels
    assert penalty.ylabel == "dv penalty vs the oracle [m/s]" and heat.ylabel == "peak total heat rate [W/cm2]"
    assert outcome.xticklabels[0].startswith("oracle: bound")
    benchmark_report.penalty_plot(tmp_path, rows, "oracle")
    (mine,) = drawn[(tmp_path / "penalty.png").resolve()].panels  # a law without a scored run has no panel
    assert mine.title == "mine: 16 of 20 runs scored\n(4 not captured by the law: no penalty)"
    assert mine.legend[0] == "the oracle (no penalty)"


def _set(folder, laws, source=AFE):
    """A set of some of the shipped AFE scenarios, the paths made absolute (the same files otherwise)."""
    folder.mkdir()
    for name, law in laws.items():
        doc = json.loads((source / f"{law}.json").read_text())
        for key in ("system", "dispersion_set"):
            doc[key] = str((source / doc[key]).resolve())
        write_json(folder / f"{name}.json", doc)
    return folder


@pytest.mark.integration
def test_every_law_is_scored_against_the_oracle_of_an_afe_set_whose_rows_are_reused(tmp_path, drawn):
    folder = _set(tmp_path / "set", {"npc_bank": "npc_bank", "oracle": "oracle", "time_linear": "time_linear"})
    result = CliRunner().invoke(main, ["benchmark", str(folder), "--runs", "6", "--out", str(tmp_path / "o")])
    assert result.exit_code == 0, result.output  # the time-linear law reaches the ground in every run: an outcome
    assert "every one of its" not in result.output
    flown = [line for line in result.output.splitlines() if ": flying 6 runs" in line]
    assert flown[0].startswith("oracle: flying 6 runs"), result.output  # the bound first
    assert "oracle is the set's oracle, the bound, not a competitor" in result.output
    out = tmp_path / "o"
    card = {c["law"]: c for c in json.loads((out / "scorecard.json").read_text())["scorecard"]}
    assert list(card) == ["oracle", "npc_bank", "time_linear"]
    assert [card[law]["role"] for law in card] == ["oracle", "law", "law"]
    assert card["oracle"]["dv_penalty_p50"] is None and card["time_linear"]["dv_penalty_p50"] is None
    table = pq.read_table(out / "rows.parquet")
    for column, unit in oracle_score.COLUMNS:
        assert table.schema.field(column).metadata[b"unit"] == unit.encode()
    rows = table.to_pylist()
    by_law = {law: [r for r in rows if r["law"] == law] for law in card}
    own = {law: pq.read_table(out / law / "rows.parquet").to_pylist() for law in card}
    for law in card:  # every law's rows are its campaign's rows, the joined columns added
        assert repr([{k: v for k, v in r.items() if k in own[law][0]} for r in by_law[law]]) == repr(own[law])
    oracle_dv = {r["run"]: r["outcome.dv_total"] for r in own["oracle"]}
    both = [r for r in own["npc_bank"] if r["outcome"] == "captured"]
    assert len(both) >= 4 and all(r["outcome"] == "captured" for r in own["oracle"])
    penalty = np.array([r["outcome.dv_total"] - oracle_dv[r["run"]] for r in both])
    assert card["npc_bank"]["dv_penalty_p50"] == np.percentile(penalty, 50.0) > 0
    assert card["npc_bank"]["dv_penalty_p99.865"] == np.percentile(penalty, 99.865)
    assert "| role | oracle | law | law |" in (out / "report.md").read_text()
    assert "![penalty.png](penalty.png)" in (out / "report.md").read_text()
    names = [p.ylabel.split(" [")[0] for p in drawn[(out / "benchmark.png").resolve()].panels[1:]]
    assert names[1:4] == ["correction dv", "dv penalty vs the oracle", "peak total heat rate"]
    again = run_benchmark(BenchmarkOptions(scenario_set=folder, runs=6, out=out))
    assert again["laws"]["oracle"]["reused"] and again["laws"]["npc_bank"]["reused"]  # the oracle's rows reused
    assert repr(pq.read_table(out / "rows.parquet").to_pylist()) == repr(rows)
    assert again["scorecard"][1]["dv_penalty_p50"] == card["npc_bank"]["dv_penalty_p50"]


@pytest.mark.integration
def test_a_set_without_an_oracle_is_scored_as_before(tmp_path):
    folder = _set(tmp_path / "set", {"npc_bank": "npc_bank"})
    result = run_benchmark(BenchmarkOptions(scenario_set=folder, runs=2, out=tmp_path / "o"))
    assert result["oracle"] is None and "role" not in result["units"]
    assert not any(c.startswith("dv_penalty") for c in result["units"])
    assert not any(c.startswith("oracle.") for c in pq.read_table(tmp_path / "o" / "rows.parquet").column_names)
    assert result["plots"] == ["benchmark.png"] and not (tmp_path / "o" / "penalty.png").exists()


@pytest.mark.integration
def test_two_oracles_in_a_set_are_refused_in_one_line(tmp_path):
    folder = _set(tmp_path / "set", {"oracle": "oracle", "oracle_copy": "oracle"})
    result = CliRunner().invoke(main, ["benchmark", str(folder), "--runs", "2", "--out", str(tmp_path / "o")])
    assert result.exit_code == 2, result.output
    assert result.output.strip().splitlines() == [
        f"error: {folder / 'oracle_copy.json'}: montecarlo.oracle: a second oracle: oracle.json is the set's oracle "
        "already; keep \"oracle\": true in one scenario of the set: the others are laws scored against it"]
    assert not (tmp_path / "o").exists()


@pytest.mark.integration
def test_a_law_given_with_law_cannot_be_the_oracle(tmp_path):
    folder = _set(tmp_path / "set", {"npc_bank": "npc_bank"})  # a set without an oracle: still refused
    mine = _set(tmp_path / "mine", {"best": "oracle"}) / "best.json"
    with pytest.raises(InputError, match=r"best\.json: montecarlo\.oracle: a law given with --law cannot be the "
                                         r"set's oracle"):
        run_benchmark(BenchmarkOptions(scenario_set=folder, laws=[mine], runs=2, out=tmp_path / "o"))
    assert not (tmp_path / "o").exists()


@pytest.mark.integration
def test_the_oracle_is_read_from_the_typed_settings():
    from aotv_cosim.simulation.loading import load_scenario

    assert load_scenario(AFE / "oracle.json").oracle is True
    assert load_scenario(AFE / "npc_bank.json").oracle is False
    loaded = benchmark.scenarios_of(AFE)
    assert oracle_score.of_set(loaded) == "oracle" and oracle_score.first_law(loaded)[0].name == "adaptive.json"
