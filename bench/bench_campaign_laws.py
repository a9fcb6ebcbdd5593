"""Campaign CPU per run of every law of the seed-000 guidance benchmark (scenarios/benchmark_seed000),
and each law's ratio to the time-linear law's.

    python bench/bench_campaign_laws.py [--runs 200] [--workers 1,2] [--repeats 3] [--laws time_linear,npc]
                                        [--big 1000]

Per law (the benchmark's dispersion set: entry state, K and density):

- in one process: CPU per run on FMUs reused as a worker reuses them, median of --repeats
  batches of --batch runs, the first run (instantiation, solves cached per process) left out,
  with --blas-threads BLAS threads (1: OpenBLAS threads spin after each call and their CPU time
  counts, so a law with small matrix calls costs 1.6 times more with a thread per core on 2
  cores). Measured in a forked child, so this process never loads a law's FMUs or imports;
- on W local workers for each W of --workers: a --runs campaign as `aotv-cosim montecarlo` runs
  it (this process has not imported scipy, as the command line has not), its CPU per run (the
  CPU time of every worker process, from getrusage of the children, over the runs: worker start,
  imports and instantiation included), its wall time, and the parallel efficiency
  t_1 / (W t_W) against the first W, whose rows must be identical;
- with --big N: the wall time of N runs on 2 workers.

The ratios to the time-linear law's CPU per run are taken in the same bench run; absolute figures
move with the machine's load (the load average at the start is printed).
"""

import argparse
import concurrent.futures as cf
import multiprocessing
import os
import resource
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LAWS = ROOT / "scenarios" / "benchmark_seed000"
REFERENCE_LAW = "time_linear"
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS")
"""What a campaign worker sets (campaigns.backends), spelled here so the bench runs on older trees."""


def _in_process_ms(scenario, repeats, batch, blas_threads):
    from threadpoolctl import threadpool_limits

    from aotv_cosim.campaigns.draws import draw
    from aotv_cosim.campaigns.scenario_ref import ScenarioRef
    from aotv_cosim.campaigns.worker import Runner

    os.environ.update(dict.fromkeys(BLAS_THREAD_VARIABLES, str(blas_threads)))
    threadpool_limits(limits=blas_threads, user_api="blas")
    runner = Runner(ScenarioRef.of(scenario))
    draws = [draw(runner.scenario.dispersions, 0, k) for k in range(batch + 1)]
    runner.run(0, draws[0])
    times = []
    for _ in range(repeats):
        t0 = time.process_time()
        for k, values in enumerate(draws[1:], 1):
            runner.run(k, values)
        times.append((time.process_time() - t0) / batch * 1e3)
    return statistics.median(times)


def in_process_ms_per_run(scenario, repeats: int = 3, batch: int = 10, blas_threads: int = 1) -> float:
    """CPU ms per run of `scenario` in one process on reused FMUs (median of `repeats` batches of
    `batch` runs) with `blas_threads` BLAS threads, measured in a forked child process that is
    then discarded."""
    context = multiprocessing.get_context("fork")
    with cf.ProcessPoolExecutor(1, mp_context=context) as pool:
        return pool.submit(_in_process_ms, str(scenario), repeats, batch, blas_threads).result()


def _children_cpu():
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def campaign(scenario, runs: int, workers: int, out: Path) -> dict:
    """A `runs`-run campaign on `workers` local workers: wall s, CPU ms per run of the workers
    (children's CPU time over the runs) and the rows.csv text."""
    from aotv_cosim.campaigns import run_campaign
    from aotv_cosim.options import CampaignOptions

    cpu0, t0 = _children_cpu(), time.perf_counter()
    summary = run_campaign(CampaignOptions(scenario=scenario, runs=runs, out=out, workers=workers, plots=False))
    wall, cpu = time.perf_counter() - t0, _children_cpu() - cpu0
    assert summary["statuses"].get("completed", 0) + summary["statuses"].get("failed", 0) == runs, summary
    return {"wall": wall, "cpu_ms": cpu / runs * 1e3, "rows": (out / "rows.csv").read_text()}


def law_figures(path: Path, args) -> dict:
    in_process = in_process_ms_per_run(path, args.repeats, args.batch, args.blas_threads)
    figures = {"law": path.stem, "in_process": in_process}
    with tempfile.TemporaryDirectory() as tmp:
        for w in args.workers:
            figures[w] = campaign(path, args.runs, w, Path(tmp) / f"w{w}")
        if args.big:
            figures["big"] = campaign(path, args.big, 2, Path(tmp) / "big")["wall"]
    return figures


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=200, help="runs of each campaign")
    parser.add_argument("--workers", default="1,2", help="worker counts of the campaigns ('': none)")
    parser.add_argument("--repeats", type=int, default=3, help="batches for the in-process CPU per run")
    parser.add_argument("--batch", type=int, default=10, help="runs per batch in one process")
    parser.add_argument("--blas-threads", type=int, default=1, help="BLAS threads in one process")
    parser.add_argument("--big", type=int, default=0, help="also time this many runs on 2 workers")
    parser.add_argument("--laws", default="", help="comma-separated scenario names (default: every law)")
    args = parser.parse_args()
    args.workers = [int(w) for w in args.workers.split(",") if w]
    sys.path.insert(0, str(ROOT))
    chosen = [name for name in args.laws.split(",") if name]
    paths = sorted(LAWS.glob("*.json"))
    paths = [p for p in paths if p.stem == REFERENCE_LAW] + [p for p in paths if p.stem != REFERENCE_LAW]
    paths = [p for p in paths if not chosen or p.stem in chosen or p.stem == REFERENCE_LAW]
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; {args.runs} runs per campaign")
    w0 = args.workers[0] if args.workers else None
    head = f"{'law':<20} {'1 process ms':>12} {'x ref':>6}"
    for w in args.workers:
        head += f" {f'{w}w CPU ms':>10} {'x ref':>6} {f'{w}w wall s':>10}"
    print(head + "".join(f" {f'eff {w}w %':>9}" for w in args.workers[1:])
          + f"  rows equal{'  big wall s' if args.big else ''}")
    reference = None
    for path in paths:
        f = law_figures(path, args)
        reference = reference or f
        line = f"{f['law']:<20} {f['in_process']:>12.1f} {f['in_process'] / reference['in_process']:>6.2f}"
        for w in args.workers:
            line += f" {f[w]['cpu_ms']:>10.1f} {f[w]['cpu_ms'] / reference[w]['cpu_ms']:>6.2f} {f[w]['wall']:>10.2f}"
        line += "".join(f" {f[w0]['wall'] / (w / w0 * f[w]['wall']) * 100:>9.0f}" for w in args.workers[1:])
        line += f"  {all(f[w]['rows'] == f[w0]['rows'] for w in args.workers)}"
        print(line + (f"  {f['big']:>10.2f}" if args.big else ""), flush=True)


if __name__ == "__main__":
    main()
