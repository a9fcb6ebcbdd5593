"""Nothing of the user's lost (issue 34 item 2) and the set's problems named where the user looks:

- an output folder keeps a record of what the package wrote (.aotv-written); a file of a result's
  name that the package did not write is never overwritten, `benchmark --refly` deletes only what
  an earlier benchmark wrote (it deleted a user's notes file);
- a benchmark interrupted by SIGINT exits 130 and says what was kept (it exited 0 with a partial
  scorecard), a campaign of 10^6 runs draws its runs as they go: bounded memory, and a SIGINT ends it
  within seconds (10^9 grew to 6 GB and did not stop);
- sweep grids are checked as --set checks its values; sweeps and corridors also run on Dask;
- a --law wiring missing what the set needs is reported naming the user's file, not a generated one;
  shipped set names work from any folder, and an unknown one lists them."""

import json
import os
import re
import signal
import subprocess
import time
from pathlib import Path

import pyarrow.parquet as pq
import pytest

import aotv_cosim
from aotv_cosim.campaigns import benchmark
from aotv_cosim.errors import InputError
from aotv_cosim.output.outdir import RECORD
from tests.helpers import ROOT, SCENARIOS, command, error_lines, invoke, package_env, write_json

pytestmark = pytest.mark.integration

SET = SCENARIOS / "benchmark_seed000"
PASS = SET / "time_linear.json"
MC = SCENARIOS / "montecarlo_robust_density.json"
AFE = SCENARIOS / "benchmark_aerocapture" / "afe"


@pytest.fixture(autouse=True)
def fresh_store(tmp_path, monkeypatch):
    """No stored benchmark rows of an earlier test (they would be reused, not flown)."""
    monkeypatch.setattr(benchmark, "stored_rows_dir", lambda: tmp_path / "stored")


def _small_set(folder, laws=("time_linear",)):
    folder.mkdir()
    for law in laws:
        doc = json.loads((SET / f"{law}.json").read_text())
        doc.update(system=str((SET / doc["system"]).resolve()),
                   dispersion_set=str((SET / doc["dispersion_set"]).resolve()))
        write_json(folder / f"{law}.json", doc)
    return folder


def test_refly_deletes_only_what_a_benchmark_wrote(tmp_path):
    small = _small_set(tmp_path / "set")
    mine = write_json(tmp_path / "mine.json", json.loads((SCENARIOS / "systems" / "aotv_robust.json").read_text()))
    out = tmp_path / "out"
    args = ["benchmark", small, "--law", mine, "--runs", 2, "--out", out]
    assert invoke(*args)[0] == 0
    rows = pq.read_table(out / "rows.parquet").to_pylist()
    notes = {out / "notes.txt": "mine", out / "mine" / "notes.txt": "also mine", out / "laws" / "keep.md": "mine too"}
    for path, text in notes.items():
        path.write_text(text)
    status, text = invoke(*args, "--refly")
    assert status == 0, text
    assert {path: path.read_text() for path in notes} == notes
    assert repr(pq.read_table(out / "rows.parquet").to_pylist()) == repr(rows)
    assert "mine/rows.csv" in (out / RECORD).read_text().splitlines()


def test_a_result_file_the_package_did_not_write_is_never_overwritten(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "summary.json").write_text("the user's own summary")
    status, text = invoke("run", PASS, "--out", out, "--stop", 5)
    assert status == 2, text
    assert error_lines(text) == [f"error: {out}: --out: summary.json is there and was not written by aotv-cosim "
                                 f"(it is not in {RECORD}): it would be overwritten; move {out / 'summary.json'} away "
                                 "or choose another --out"]
    with pytest.raises(InputError, match=re.escape("summary.json is there and was not written by aotv-cosim")):
        aotv_cosim.run(PASS, out=out, stop=5)
    assert (out / "summary.json").read_text() == "the user's own summary"
    (out / "summary.json").unlink()
    assert invoke("run", PASS, "--out", out, "--stop", 5)[0] == 0
    assert invoke("run", PASS, "--out", out, "--stop", 5)[0] == 0  # its own files: rewritten


def test_a_folder_written_before_the_record_is_taken_as_the_packages(tmp_path):
    """An earlier version left .lock and its result files, and no record: they are its own."""
    out = tmp_path / "old"
    out.mkdir()
    for name in (".lock", "summary.json", "timeseries.csv", "overview.png"):
        (out / name).write_text("old")
    assert invoke("run", PASS, "--out", out, "--stop", 5, "--no-plots")[0] == 0
    assert json.loads((out / "summary.json").read_text())["status"] == "completed"


def _wait_for(path, lines, process, timeout=240.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if path.is_file() and path.read_text().count("\n") > lines:
            return
        assert process.poll() is None, process.communicate()
        time.sleep(0.1)
    pytest.fail(f"no rows in {path} in time")


def test_a_benchmark_interrupted_by_sigint_exits_130_and_says_what_it_kept(tmp_path):
    small = _small_set(tmp_path / "set", ["robust", "time_linear"])
    out = tmp_path / "out"
    process = subprocess.Popen(command("benchmark", small, "--runs", 400, "--out", out), cwd=ROOT,
                               env=package_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _wait_for(out / "robust" / "rows.csv", 3, process)
    process.send_signal(signal.SIGINT)
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == 130, (stdout, stderr)
    assert (f"interrupted by SIGINT while flying robust: its finished runs are in {out / 'robust'}; laws done before "
            "(stored for reuse when flown to the end): none; no scorecard written") in stderr
    assert not (out / "scorecard.csv").exists() and not list(out.rglob("*.part"))
    assert json.loads((out / "robust" / "summary.json").read_text())["status"] == "interrupted"


def _rss_mib(pid) -> float:
    return int(Path(f"/proc/{pid}/statm").read_text().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


def test_a_million_run_campaign_draws_as_it_goes_and_stops_on_sigint(tmp_path):
    """Every draw was made (and every task built) before the first run: 10^9 runs grew to 6 GB.
    Now the parent holds the runs in flight: its memory stays that of a small campaign."""
    out = tmp_path / "out"
    process = subprocess.Popen(command("montecarlo", MC, "--runs", 10**6, "--workers", 2, "--out", out), cwd=ROOT,
                               env=package_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    _wait_for(out / "rows.csv", 20, process)
    rss = _rss_mib(process.pid)
    t0 = time.monotonic()
    process.send_signal(signal.SIGINT)
    stdout, stderr = process.communicate(timeout=60)
    assert process.returncode == 130, (stdout, stderr)
    assert time.monotonic() - t0 < 30
    assert rss < 400, rss  # MiB; a small campaign's parent holds about 150-250
    assert "interrupted by SIGINT" in stdout and "--resume runs the other" in stdout
    assert not list(out.glob("*.part"))


def test_sweep_values_are_checked_as_set_checks_them(tmp_path):
    """A grid over a connected input was silently ignored, values outside the declared range flown."""
    cases = [("vehicle.u_lift=0,1", "input u_lift is both connected and given a value"),
             ("vehicle.gamma0=-3:-0.01:3", "gamma0 = -3.0 is outside its physical range"),
             ("vehicle.gravity_model=0,1", "vehicle.gravity_model is not a Real parameter of the system")]
    for grid, message in cases:
        status, text = invoke("sweep", PASS, "--grid", grid, "--out", tmp_path / "s")
        assert status == 2 and message in error_lines(text)[0], text
        with pytest.raises(InputError, match=message):
            aotv_cosim.sweep(PASS, [grid])
    assert not (tmp_path / "s").exists()


def test_a_law_wiring_missing_what_the_set_needs_names_the_users_file(tmp_path):
    """Issue 36: `record[10]: bank.saturation_time is not an output of the system` named a
    generated file under results/ (a wiring whose bank component has another name). The set's
    contract (`campaigns.contract`) names the user's wiring and what is missing, before any run."""
    wiring = json.loads((AFE.parent / "systems" / "afe_time_linear.json").read_text())
    wiring["components"]["steering"] = wiring["components"].pop("bank")
    wiring["connections"] = [c.replace("bank.", "steering.") for c in wiring["connections"]]
    for comp in wiring["components"].values():
        if comp["fmu"].endswith((".fmu", ".py")):
            comp["fmu"] = str((AFE.parent / "systems" / comp["fmu"]).resolve())
    mine = write_json(tmp_path / "my_bank_law.json", wiring)
    out = tmp_path / "out"
    status, text = invoke("benchmark", AFE, "--law", mine, "--runs", 1, "--out", out)
    assert status == 2, text
    line, = error_lines(text)
    assert line == (f"error: {mine}: components: no component 'bank': the set {AFE} reads bank.saturation_time [s] "
                    "(record; the outcome's actuator: saturation time); name the component of your law that provides "
                    "it 'bank'")
    with pytest.raises(InputError) as caught:
        aotv_cosim.benchmark(AFE, mine, runs=1, out=out)
    assert f"error: {caught.value}" == line
    assert not out.exists()  # refused before any run: nothing left
    wiring = json.loads((SCENARIOS / "systems" / "aotv_time_linear.json").read_text())
    wiring["components"]["law"] = wiring["components"].pop("guidance")
    wiring["connections"] = [c.replace("guidance.", "law.") for c in wiring["connections"]]
    renamed = write_json(tmp_path / "renamed.json", wiring)
    small = _small_set(tmp_path / "set")
    status, text = invoke("benchmark", small, "--law", renamed, "--runs", 1, "--out", out)
    assert status == 2 and error_lines(text) == [
        f"error: {renamed}: components: no component 'guidance': the set {small} reads guidance.u [m/s2] (record); "
        "name the component of your law that provides it 'guidance'"], text
    assert not out.exists()


def test_shipped_set_names_work_from_any_folder_and_an_unknown_one_lists_them(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for name in ("scenarios/benchmark_aerocapture/afe", "benchmark_aerocapture/afe"):
        assert [p.name for p, _ in benchmark.scenarios_of(name)][:2] == ["adaptive.json", "lqr.json"]
    missing = tmp_path / "missing.json"
    status, text = invoke("benchmark", "scenarios/benchmark_aerocapture/afe", "--law", missing, "--runs", 1)
    assert "--law: file not found" in text  # the set was found; the law was not
    status, text = invoke("benchmark", "benchmark_nosuchset", "--runs", 1)
    assert status == 2 and error_lines(text) == [
        "error: benchmark_nosuchset: not found, neither here nor among the shipped sets; give a folder of scenario "
        "files, one law each, one scenario file, or the name of a shipped set: benchmark_aerocapture/afe, "
        "benchmark_aerocapture/aotv, benchmark_seed000"]
    assert not (tmp_path / "results").exists()


def _cluster():
    from distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None)
    return cluster, Client(cluster)


def test_sweeps_and_corridors_give_the_same_results_on_dask_and_local_workers(tmp_path):
    grid = {"vehicle.gamma0": [-0.022, -0.02, -0.018], "atmosphere.density_factor": [0.9, 1.1]}
    local = aotv_cosim.sweep(PASS, grid, workers=2, fmi_calls="c", out=tmp_path / "local")
    assert local.attrs["sweep"]["fmi_calls"] == "c" and local.attrs["sweep"]["limits"]["step_timeout_s"] == 60.0
    corridor = aotv_cosim.corridor(PASS, lift_to_drag=5.0, workers=2, tolerance=500.0)
    alone = aotv_cosim.corridor(PASS, lift_to_drag=5.0, workers=1, tolerance=500.0)
    assert {k: corridor[k] for k in ("steep", "shallow")} == {k: alone[k] for k in ("steep", "shallow")}
    cluster, client = _cluster()
    with cluster, client:
        dask = aotv_cosim.sweep(PASS, grid, scheduler=client)
        on_dask = aotv_cosim.corridor(PASS, lift_to_drag=5.0, scheduler=client, tolerance=500.0)
    assert dask.attrs["sweep"]["backend"] == "dask"
    assert repr(dask.to_dict("records")) == repr(local.to_dict("records"))
    assert {k: on_dask[k] for k in ("steep", "shallow")} == {k: alone[k] for k in ("steep", "shallow")}
