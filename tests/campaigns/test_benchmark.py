"""Guidance benchmark: every law of a set over the same draws, a scorecard
with units, rows CSV + Parquet with a law column; identical rows on 1 and 2 local workers and on a
multi-process Dask cluster."""

import csv
import json
import os
import re
import shutil
import socket
import subprocess
import sys

import pyarrow.parquet as pq
import pytest
from click.testing import CliRunner

from aotv_cosim.campaigns import benchmark, benchmark_report
from aotv_cosim.campaigns.benchmark import run_benchmark
from aotv_cosim.options import BenchmarkOptions
from aotv_cosim.cli import main
from aotv_cosim.errors import InputError
from tests.helpers import SCENARIOS, write_json

BENCH = SCENARIOS / "benchmark_seed000"


@pytest.fixture(autouse=True)
def fresh_store(tmp_path, monkeypatch):
    """Each test starts with no stored campaign rows (they would be reused, not flown)."""
    monkeypatch.setattr(benchmark, "stored_rows_dir", lambda: tmp_path / "stored")


def _small_set(folder, laws):
    """A set of some of the shipped laws, the paths made absolute (the same files otherwise)."""
    folder.mkdir()
    for law in laws:
        doc = json.loads((BENCH / f"{law}.json").read_text())
        for key in ("system", "dispersion_set"):
            doc[key] = str((BENCH / doc[key]).resolve())
        write_json(folder / f"{law}.json", doc)
    return folder


@pytest.mark.integration
def test_cli_benchmark_scorecard_rows_and_report(tmp_path, drawn):
    folder = _small_set(tmp_path / "set", ["time_linear", "npc"])
    result = CliRunner().invoke(main, ["benchmark", str(folder), "--runs", "3", "--out", str(tmp_path / "o")])
    assert result.exit_code == 0, result.output
    assert "capture_rate [%]" in result.output and "apogee_error_p50 [km]" in result.output  # display units
    out = tmp_path / "o"
    with open(out / "scorecard.csv") as f:
        cards = {r["law"]: r for r in csv.DictReader(f)}
    assert set(cards) == {"time_linear", "npc"}
    # the NPC law targets the exit apogee and meets it; the open-loop time-linear law does not
    assert cards["npc"]["captured [1]"] == "3" and cards["time_linear"]["captured [1]"] == "0"
    assert float(cards["npc"]["cpu_per_run [s]"]) > 0
    table = pq.read_table(out / "rows.parquet")
    assert table.schema.field("outcome.dv_total").metadata[b"unit"] == b"m/s"
    rows = table.to_pylist()
    by_law = {law: [r for r in rows if r["law"] == law] for law in cards}
    dispersed = [c for c in table.column_names if c.startswith("dispersed.")]
    assert len(dispersed) == 4
    for a, b in zip(by_law["npc"], by_law["time_linear"]):  # same run, same draws, whatever the law
        assert [a[c] for c in dispersed] == [b[c] for c in dispersed]
    assert "| capture_rate [%] |" in (out / "report.md").read_text()
    assert (out / "benchmark.png").is_file() and (out / "npc" / "report.md").is_file()
    outcomes, *panels = drawn[(out / "benchmark.png").resolve()].panels  # the outcomes, a panel a metric
    shown = benchmark_report.panels_of(by_law)
    assert (outcomes.title, outcomes.ylabel) == ("outcome", "runs [%]")
    names = [p.ylabel.split(" [")[0] for p in panels]  # a metric without a finite value has no panel
    assert len(names) >= 4 and names == [name for _, name, _ in shown if name in names]
    # seed 000's vehicle has no radiative heating: the convective heating is drawn; no oracle, no penalty
    assert "peak heat rate" in names and "dv penalty vs the oracle" not in names
    assert not (out / "penalty.png").exists() and "role" not in cards["npc"]
    assert not any(name.startswith("oracle.") for name in table.column_names)
    assert panels[0].ylabel == "apogee error [km]" and panels[0].legend[0].startswith("capture band +-")
    assert panels[0].yscale == "symlog"


def test_benchmark_of_a_folder_without_scenarios_is_an_input_error(tmp_path):
    (tmp_path / "empty").mkdir()
    result = CliRunner().invoke(main, ["benchmark", str(tmp_path / "empty"), "--runs", "2",
                                       "--out", str(tmp_path / "o")])
    assert result.exit_code == 2
    assert result.output.strip().splitlines() == [
        f"error: {tmp_path / 'empty'}: the folder holds no scenario file; put one *.json scenario per law in it"]


@pytest.mark.integration
def test_a_law_that_does_not_classify_or_records_other_columns_is_refused_before_any_run(tmp_path):
    folder = _small_set(tmp_path / "set", ["robust", "time_linear"])
    doc = json.loads((folder / "time_linear.json").read_text())
    doc["record"] = doc["record"][:-1]
    write_json(folder / "time_linear.json", doc)
    with pytest.raises(InputError, match=re.escape("time_linear.json: record: its campaign columns differ from those "
                                                   "of robust")):
        run_benchmark(BenchmarkOptions(scenario_set=folder, runs=2, out=tmp_path / "o"))
    del doc["montecarlo"]["outcome"]
    write_json(folder / "time_linear.json", doc)
    with pytest.raises(InputError, match="montecarlo: the scenario does not classify its runs"):
        run_benchmark(BenchmarkOptions(scenario_set=folder, runs=2, out=tmp_path / "o"))
    assert not (tmp_path / "o").exists()


@pytest.mark.integration
def test_one_law_benchmark_flies_the_law_and_reuses_the_stored_rows_of_the_others(tmp_path):
    folder = _small_set(tmp_path / "set", ["time_linear", "robust"])
    mine = write_json(tmp_path / "my_law.json",
                      json.loads((SCENARIOS / "systems" / "aotv_time_linear.json").read_text()))
    result = CliRunner().invoke(main, ["benchmark", str(folder), "--law", str(mine), "--runs", "3",
                                       "--out", str(tmp_path / "o")])
    assert result.exit_code == 0, result.output
    assert "time_linear: flying 3 runs" in result.output
    # my_law is time_linear's wiring under another name: the same campaign, so its rows are reused
    assert "my_law: 3 stored runs reused" in result.output
    rows = pq.read_table(tmp_path / "o" / "rows.parquet").to_pylist()
    by_law = {law: [{k: v for k, v in r.items() if k != "law"} for r in rows if r["law"] == law]
              for law in ("time_linear", "my_law")}
    assert repr(by_law["my_law"]) == repr(by_law["time_linear"])
    flown = sorted((tmp_path / "o").iterdir())
    again = run_benchmark(BenchmarkOptions(scenario_set=folder, runs=3, out=tmp_path / "o", laws=[mine]))
    assert {law: info["reused"] for law, info in again["laws"].items()} == {
        "robust": True, "time_linear": True, "my_law": True}
    assert repr(pq.read_table(tmp_path / "o" / "rows.parquet").to_pylist()) == repr(rows)
    assert sorted((tmp_path / "o").iterdir()) == flown
    other_n = run_benchmark(BenchmarkOptions(scenario_set=folder / "robust.json", runs=2, out=tmp_path / "o2",
                                             laws=[mine]))
    assert [c["law"] for c in other_n["scorecard"]] == ["robust", "my_law"]
    assert not any(info["reused"] for info in other_n["laws"].values())  # N changed: flown
    assert (tmp_path / "o2" / "my_law" / "rows.parquet").is_file()


@pytest.mark.integration
def test_a_law_named_like_one_of_the_set_is_refused(tmp_path):
    folder = _small_set(tmp_path / "set", ["time_linear"])
    clash = write_json(tmp_path / "time_linear.json",
                       json.loads((SCENARIOS / "systems" / "aotv_robust.json").read_text()))
    with pytest.raises(InputError, match="a law named 'time_linear' is already in the set"):
        run_benchmark(BenchmarkOptions(scenario_set=folder, runs=2, out=tmp_path / "o", laws=[clash]))


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _cluster_rows(folder, runs, out):
    """Rows of a benchmark on a scheduler and two worker processes started by the dask commands."""
    dask = shutil.which("dask") or pytest.skip("no dask command")
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    procs = [subprocess.Popen([dask, "scheduler", "--host", "127.0.0.1", "--port", str(port),
                               "--no-dashboard"], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        for _ in range(2):
            procs.append(subprocess.Popen([dask, "worker", address, "--nworkers", "1", "--nthreads", "1",
                                           "--no-dashboard", "--host", "127.0.0.1"], env=env,
                                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        from distributed import Client

        with Client(address, timeout=60) as client:
            client.wait_for_workers(2, timeout=120)
            pids = set(client.run(os.getpid).values())
            assert len(pids) == 2 and os.getpid() not in pids  # two real worker processes
        result = run_benchmark(BenchmarkOptions(scenario_set=folder, runs=runs, out=out, seed=11, scheduler=address,
                                                reuse=False))
        assert all(card["cpu_per_run"] is None for card in result["scorecard"])  # not seen from here
        return pq.read_table(out / "rows.parquet").to_pylist()
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in procs:
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()


def _local_and_cluster(tmp_path, laws, runs):
    folder = _small_set(tmp_path / "set", laws)
    run_benchmark(BenchmarkOptions(scenario_set=folder, runs=runs, out=tmp_path / "local", workers=2, seed=11))
    local = pq.read_table(tmp_path / "local" / "rows.parquet").to_pylist()
    run_benchmark(BenchmarkOptions(scenario_set=folder, runs=runs, out=tmp_path / "one", workers=1, seed=11,
                                   reuse=False))
    assert repr(pq.read_table(tmp_path / "one" / "rows.parquet").to_pylist()) == repr(local)  # 1 = 2 workers
    cluster = _cluster_rows(folder, runs, tmp_path / "dask")
    assert repr(local) == repr(cluster)  # every value the same (repr: nan equals nan)
    return local


@pytest.mark.integration
def test_40_run_benchmark_on_a_two_process_dask_cluster_equals_the_local_run(tmp_path):
    rows = _local_and_cluster(tmp_path, ["time_linear", "robust"], 40)
    assert len(rows) == 80


@pytest.mark.integration
@pytest.mark.slow
def test_40_run_benchmark_of_every_law_on_a_dask_cluster_equals_the_local_run(tmp_path):
    rows = _local_and_cluster(tmp_path, [p.stem for p in sorted(BENCH.glob("*.json"))], 40)
    assert len(rows) == 8 * 40
