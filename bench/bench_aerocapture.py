"""The aerocapture sets' cost: the bank NPCs' and the oracle's CPU per run against the time-linear
law's, and a set's N = 1000 benchmark wall time, in this tree and in another checkout.

    python bench/bench_aerocapture.py OTHER_TREE [--set afe] [--runs 10] [--rounds 3]
                                      [--laws time_linear,npc_bank,npc_bank_density,oracle] [--big 1000]
                                      [--workers 2]

1. CPU per run in one process, FMUs reused as a campaign worker reuses them (the first run,
   instantiation and solves cached per process, left out), of each of --laws in each tree: a fresh
   process per tree and round (PYTHONPATH set to the tree, one BLAS thread), the laws alternated
   inside it, the trees alternated over --rounds rounds; per tree the median over rounds of each
   law's CPU per run and its ratio to the time-linear law's taken in the same process. A law the
   tree lacks is left out of its column.
2. With --big N: `aotv-cosim benchmark SET --runs N --workers W --refly` in the other tree, then in
   this one (one round each: a round takes minutes), each timed by its wall clock; the FMUs are
   built first, outside the timing. Prints each tree's wall time, its laws' campaign wall times
   and cpu_per_run from scorecard.json, and the ratio of the wall times over the laws both trees
   have.

Absolute figures move with the machine's load (printed at the start and with each round); the
ratios are taken in the same process (1) or the same bench run (2). The bank NPC's CPU per run
must be at most 3 times the time-linear law's (issue 36 item 5); the oracle's (`oracle.json`, whose
solve at initialization is most of its run) at most the bank NPC's.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))

from timing import machine  # noqa: E402 - found through the sys.path entry just above

REFERENCE_LAW = "time_linear"

CPU_PER_RUN = r'''
import json, os, sys, time
os.environ.update(OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1")
from aotv_cosim.campaigns.draws import draw
from aotv_cosim.campaigns.scenario_ref import ScenarioRef
from aotv_cosim.campaigns.worker import Runner

folder, runs, laws = sys.argv[1], int(sys.argv[2]), sys.argv[3].split(",")
runners = {}
for law in laws:
    path = os.path.join(folder, law + ".json")
    if os.path.isfile(path):
        runner = Runner(ScenarioRef.of(path))
        draws = [draw(runner.scenario.dispersions, 0, k) for k in range(runs + 1)]
        runner.run(0, draws[0])
        runners[law] = (runner, draws)
cpu = {law: 0.0 for law in runners}
for k in range(1, runs + 1):  # the laws alternated run by run
    for law, (runner, draws) in runners.items():
        t0 = time.process_time()
        runner.run(k, draws[k])
        cpu[law] += time.process_time() - t0
print(json.dumps({law: seconds / runs for law, seconds in cpu.items()}))
'''


def _env(tree: Path) -> dict:
    return dict(os.environ, PYTHONPATH=str(tree), OPENBLAS_NUM_THREADS="1")


def cpu_per_run(tree: Path, set_name: str, runs: int, laws) -> dict:
    """{law: CPU s per run} in one process of `tree` (module docstring, 1)."""
    folder = tree / "scenarios" / "benchmark_aerocapture" / set_name
    done = subprocess.run([sys.executable, "-c", CPU_PER_RUN, str(folder), str(runs), ",".join(laws)], cwd=tree,
                          env=_env(tree), check=True, capture_output=True, text=True)
    return json.loads(done.stdout.splitlines()[-1])


def benchmark_wall(tree: Path, set_name: str, runs: int, workers: int) -> dict:
    """Wall s of `aotv-cosim benchmark` of the set in `tree` and its scorecard.json (module docstring, 2)."""
    set_path = tree / "scenarios" / "benchmark_aerocapture" / set_name
    subprocess.run([sys.executable, "-m", "aotv_cosim", "build-fmus"], cwd=tree, env=_env(tree), check=True,
                   capture_output=True)
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "aotv_cosim", "benchmark", str(set_path), "--runs", str(runs),
                        "--workers", str(workers), "--refly", "--out", tmp], cwd=tree, env=_env(tree), check=True,
                       capture_output=True)
        wall = time.perf_counter() - t0
        scorecard = json.loads((Path(tmp) / "scorecard.json").read_text())
    return {"wall": wall, "laws": {law: info["wall_time_s"] for law, info in scorecard["laws"].items()},
            "cpu_per_run": {card["law"]: card["cpu_per_run"] for card in scorecard["scorecard"]}}


def _cpu_table(trees, results, laws):
    print(f"{'law':<20}" + "".join(f" {name + ' ms':>14} {'x ' + REFERENCE_LAW:>16}" for name in trees))
    for law in laws:
        line = f"{law:<20}"
        for name in trees:
            values = [r[law] for r in results[name] if law in r]
            ratios = [r[law] / r[REFERENCE_LAW] for r in results[name] if law in r and REFERENCE_LAW in r]
            line += (f" {statistics.median(values) * 1e3:>14.1f} {statistics.median(ratios):>16.2f}" if values
                     else f" {'-':>14} {'-':>16}")
        print(line)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("other", type=Path, help="the other checkout (a git worktree)")
    parser.add_argument("--set", default="afe", choices=("afe", "aotv"), help="the aerocapture set")
    parser.add_argument("--runs", type=int, default=10, help="runs per law per process for the CPU per run")
    parser.add_argument("--rounds", type=int, default=3, help="processes per tree for the CPU per run")
    parser.add_argument("--laws", default="time_linear,npc_bank,npc_bank_density,oracle")
    parser.add_argument("--big", type=int, default=0, help="also time the set's benchmark of this many runs")
    parser.add_argument("--workers", type=int, default=2, help="workers of the --big benchmark")
    args = parser.parse_args()
    trees = {"other": args.other.resolve(), "this": ROOT}
    laws = [REFERENCE_LAW] + [law for law in args.laws.split(",") if law and law != REFERENCE_LAW]
    print(machine())
    print(f"set {args.set}; other tree {trees['other']}; {args.runs} runs per law per process")
    results = {name: [] for name in trees}
    for k in range(args.rounds):
        for name, tree in trees.items():
            results[name].append(cpu_per_run(tree, args.set, args.runs, laws))
        print(f"round {k + 1}: " + "; ".join(f"{name} " + ", ".join(f"{law} {s * 1e3:.1f} ms"
                                                                    for law, s in r[-1].items())
                                           for name, r in results.items()) + f" (load {os.getloadavg()[0]:.1f})",
              flush=True)
    _cpu_table(trees, results, laws)
    if not args.big:
        return
    walls = {}
    for name, tree in trees.items():
        walls[name] = benchmark_wall(tree, args.set, args.big, args.workers)
        w = walls[name]
        print(f"{name}: benchmark {args.set} N = {args.big} on {args.workers} workers: {w['wall']:.1f} s wall "
              f"(load {os.getloadavg()[0]:.1f}); per law wall s / cpu_per_run s: "
              + ", ".join(f"{law} {s:.1f} / {w['cpu_per_run'][law]:.4f}" for law, s in w["laws"].items()), flush=True)
    common = sorted(set(walls["this"]["laws"]) & set(walls["other"]["laws"]))
    this_common = sum(walls["this"]["laws"][law] for law in common)
    other_common = sum(walls["other"]["laws"][law] for law in common)
    print(f"campaign wall over the {len(common)} laws both trees have: this {this_common:.1f} s, other "
          f"{other_common:.1f} s, this / other {this_common / other_common:.3f}; whole command this / other "
          f"{walls['this']['wall'] / walls['other']['wall']:.3f}")


if __name__ == "__main__":
    main()
