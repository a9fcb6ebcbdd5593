"""Monte Carlo campaigns: seeds per run, identical rows on the local pool and on Dask, resume,
failing and crashing runs recorded while the campaign goes on."""

import csv
import json
import textwrap
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pyarrow.parquet as pq
import pytest

from aotv_cosim.errors import InputError
from aotv_cosim.campaigns import run_campaign
from aotv_cosim.options import CampaignOptions
from aotv_cosim.campaigns.draws import draw
from aotv_cosim.campaigns.scenario_ref import ScenarioRef
from aotv_cosim.campaigns.statistics import ellipse_3sigma
from aotv_cosim.model.scenario import Dispersion
from aotv_cosim.simulation.loading import load_scenario
from tests.helpers import SCENARIOS, write_json

CAMPAIGN = SCENARIOS / "montecarlo_time_linear_density.json"


def _rows(out):
    return (out / "rows.csv").read_text()


@pytest.fixture(scope="module")
def local_20(tmp_path_factory):
    out = tmp_path_factory.mktemp("local")
    summary = run_campaign(CampaignOptions(scenario=CAMPAIGN, runs=20, out=out, workers=2, seed=7))
    return summary, out


@pytest.mark.integration
def test_local_campaign_rows_and_report(local_20):
    summary, out = local_20
    assert summary["statuses"] == {"completed": 20}
    assert repr(summary["statuses"]) == "{'completed': 20}"  # as the console prints it
    with open(out / "rows.csv") as f:
        rows = list(csv.DictReader(f))
    assert [int(r["run"]) for r in rows] == list(range(20))
    rho = np.array([float(r["dispersed.atmosphere.rho_ref"]) for r in rows])
    assert np.all((rho >= 1.4016) & (rho <= 2.1024))
    # denser air brakes more: exit speed falls with rho_ref
    v_exit = np.array([float(r["exit.vehicle.v"]) for r in rows])
    assert np.corrcoef(rho, v_exit)[0, 1] < -0.99
    table = pq.read_table(out / "rows.parquet")
    assert table.num_rows == 20 and table.column("exit.vehicle.v").to_pylist() == list(v_exit)
    stats = summary["statistics"]["exit.vehicle.v"]
    assert stats["p5"] < stats["p50"] < stats["p95"]
    assert {"histograms.png", "scatter.png"} <= set(summary["plots"])


@pytest.mark.integration
def test_dask_local_cluster_gives_identical_rows(local_20, tmp_path):
    from distributed import Client, LocalCluster

    _, local_out = local_20
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        summary = run_campaign(CampaignOptions(scenario=CAMPAIGN, runs=20, out=tmp_path, seed=7, scheduler=client,
                                               plots=False))
    assert summary["backend"] == "dask"
    assert _rows(tmp_path) == _rows(local_out)


@pytest.mark.integration
def test_dask_cluster_without_workers_fails_instead_of_waiting():
    """Workers that die at start (one that cannot import aotv_cosim) leave no worker: the campaign
    fails with one line after the patience instead of waiting forever."""
    from distributed import Client, LocalCluster

    from aotv_cosim.campaigns import backends
    from aotv_cosim.errors import SimulationError

    with LocalCluster(n_workers=0, processes=False, dashboard_address=None) as cluster, Client(cluster) as client:
        backend = backends.Dask(CampaignOptions(scenario=CAMPAIGN, runs=1, scheduler=client), ["run"], patience=1.0)
        rows = backends.stream(backend, ScenarioRef.of(CAMPAIGN), [(0, {})], 1)
        with pytest.raises(SimulationError, match="no worker for 1 s with 1 batch"):
            list(rows)


def _blas_threads():
    from threadpoolctl import threadpool_info

    return [info["num_threads"] for info in threadpool_info() if info["user_api"] == "blas"]


def test_local_workers_use_their_share_of_the_blas_threads(monkeypatch, tmp_path):
    """Even a lone local worker runs one BLAS thread (`backends.WORKER_BLAS_THREADS`): OpenBLAS
    threads spin while they wait, and two workers with a thread per core each ran the LQR law's
    1000 runs 2.3 times slower on 2 cores; one worker with two threads cost 1.5x the CPU. The limit
    is what the worker's initializer asks for, and what its BLAS then runs."""
    from aotv_cosim.campaigns import backends

    share = backends.WORKER_BLAS_THREADS
    pool = backends._pool(1)
    try:
        assert all(n <= share for n in pool.submit(_blas_threads).result())
    finally:
        pool.shutdown()
    limit = tmp_path / "limit"
    monkeypatch.setattr(backends, "threadpool_limits",
                        lambda limits, user_api: limit.write_text(f"{limits} {user_api}"))
    pool = backends._pool(2)
    try:
        pool.submit(int).result()
    finally:
        pool.shutdown()
    assert limit.read_text() == f"{share} blas"


@pytest.mark.integration
def test_resume_skips_finished_runs_and_ends_with_the_same_rows(local_20, tmp_path):
    _, local_out = local_20
    lines = _rows(local_out).splitlines(keepends=True)
    # an interrupted campaign: runs 0-4 and 9 written, then a line cut short by the interruption
    (tmp_path / "rows.csv").write_text("".join([*lines[:6], lines[10], lines[11][:30]]))
    (tmp_path / "campaign.json").write_text((local_out / "campaign.json").read_text())
    summary = run_campaign(CampaignOptions(scenario=CAMPAIGN, runs=20, out=tmp_path, workers=1, seed=7, resume=True,
                                           plots=False))
    assert summary["runs_this_session"] == 14
    assert _rows(tmp_path) == _rows(local_out)


@pytest.mark.integration
def test_resume_refuses_another_campaign(local_20, tmp_path):
    _, local_out = local_20
    (tmp_path / "campaign.json").write_text((local_out / "campaign.json").read_text())
    with pytest.raises(InputError, match="different campaign"):
        run_campaign(CampaignOptions(scenario=CAMPAIGN, runs=20, out=tmp_path, seed=8, resume=True))


def test_draws_depend_only_on_campaign_seed_and_run():
    """Run k's values come from SeedSequence(seed, spawn_key=(k,)), numpy's spawn child k."""
    dispersions = [Dispersion("a.x", "uniform", low=0.0, high=1.0),
                   Dispersion("a.y", "normal", mean=5.0, std=2.0),
                   Dispersion("a.z", "truncated_normal", mean=0.0, std=1.0, low=-0.5, high=0.5)]
    children = np.random.SeedSequence(3).spawn(4)
    for k, child in enumerate(children):
        rng = np.random.default_rng(child)
        assert draw(dispersions, 3, k)["a.x"] == rng.uniform(0.0, 1.0)
    values = [draw(dispersions, 3, k)["a.z"] for k in range(200)]
    assert min(values) >= -0.5 and max(values) <= 0.5
    assert draw(dispersions, 3, 5) == draw(dispersions, 3, 5) != draw(dispersions, 4, 5)


def test_three_sigma_ellipse_covers_its_axes():
    rng = np.random.default_rng(0)
    x = rng.normal(0.0, 2.0, 4000)
    y = 0.5 * x + rng.normal(0.0, 0.1, 4000)
    ex, _ey = ellipse_3sigma(x, y)
    assert np.max(np.abs(ex)) == pytest.approx(6.0, rel=0.05)


@pytest.mark.integration
def test_fmus_run_in_this_process_do_not_shadow_the_package_for_spawned_workers(local_20):
    """pythonfmu puts each FMU's resources folder (a partial aotv_cosim) first on sys.path; a
    process spawned afterwards (a Dask worker) would import that copy instead of the package."""
    import sys

    from aotv_cosim.simulation.master import Master

    Master(load_scenario(CAMPAIGN)).run(SimpleNamespace(record=lambda times, rows: None))
    first = next(p for p in sys.path if (Path(p or ".") / "aotv_cosim" / "__init__.py").is_file())
    assert (Path(first or ".") / "aotv_cosim" / "campaigns").is_dir(), sys.path[:4]


@pytest.mark.integration
def test_dispersion_of_a_non_parameter_is_an_input_error(tmp_path):
    doc = json.loads(CAMPAIGN.read_text())
    doc["system"] = str(CAMPAIGN.parent / doc["system"])
    doc["dispersions"] = {"vehicle.h": {"distribution": "normal", "mean": 0.0, "std": 1.0}}
    with pytest.raises(InputError, match="not a Real parameter"):
        load_scenario(write_json(tmp_path / "bad.json", doc))


CRASHY_SOURCE = textwrap.dedent('''
    import ctypes

    from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real


    class Crashy(Fmi2Slave):
        """Test FMU: y = t; ends its process natively (libc _exit, as a library would: the master
        turns Python's os._exit into a failure) once t passes crash_at (s)."""

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.crash_at = 10.0
            self.y = 0.0
            self.register_variable(Real("crash_at", causality=Fmi2Causality.parameter,
                                        variability=Fmi2Variability.fixed))
            self.register_variable(Real("y", causality=Fmi2Causality.output))

        def do_step(self, current_time, step_size):
            self.y = current_time + step_size
            if self.y > self.crash_at:
                ctypes.CDLL(None)._exit(3)
            return True
''')


def _campaign_of(tmp_path, fmu, name, parameter, low, high):
    wiring = write_json(tmp_path / "w.json", {"components": {"f": {"fmu": str(fmu)}}, "connections": []})
    return write_json(tmp_path / f"{name}.json", {
        "system": str(wiring), "stop": 1.0, "step": 0.1, "record": ["f.y"],
        "dispersions": {f"f.{parameter}": {"distribution": "uniform", "low": low, "high": high}}})


@pytest.mark.integration
def test_failing_runs_are_recorded_and_the_campaign_goes_on(tmp_path, faulty_fmu):
    scenario = _campaign_of(tmp_path, faulty_fmu, "faulty", "fail_at", 0.5, 1.5)
    summary = run_campaign(CampaignOptions(scenario=scenario, runs=12, out=tmp_path / "out", workers=2, seed=1,
                                           plots=False))
    with open(tmp_path / "out" / "rows.csv") as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        fails = float(r["dispersed.f.fail_at"]) < 1.0
        assert r["status"] == ("failed" if fails else "completed"), r
        assert ("injected fault" in r["error"]) == fails
    assert 0 < summary["statuses"]["failed"] < 12


@pytest.mark.integration
def test_crashing_runs_are_recorded_and_the_campaign_goes_on(tmp_path):
    from pythonfmu.builder import FmuBuilder

    (tmp_path / "Crashy.py").write_text(CRASHY_SOURCE)
    fmu = FmuBuilder.build_FMU(tmp_path / "Crashy.py", dest=tmp_path / "Crashy.fmu")
    scenario = _campaign_of(tmp_path, fmu, "crashy", "crash_at", 0.75, 2.75)
    summary = run_campaign(CampaignOptions(scenario=scenario, runs=8, out=tmp_path / "out", workers=2, seed=2,
                                           plots=False))
    with open(tmp_path / "out" / "rows.csv") as f:
        rows = list(csv.DictReader(f))
    assert [int(r["run"]) for r in rows] == list(range(8))
    for r in rows:
        crashes = float(r["dispersed.f.crash_at"]) < 1.0
        assert r["status"] == ("failed" if crashes else "completed"), r
        assert (r["error"] == "crash: the worker process exited with status 3 during this run "
                              "(worker replaced)") == crashes, r
    assert 0 < summary["statuses"].get("failed", 0) < 8
