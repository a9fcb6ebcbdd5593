"""Issue 17 target 3 for every law of the seed-000 guidance benchmark (scenarios/benchmark_seed000).

    python bench/bench_campaign_laws.py [--runs 1000] [--eff-runs 200] [--repeats 3] [--laws robust,npc]

Per law, the figures bench/run.py gives for the robust-law density campaign, with the same
definitions and targets: CPU per run in one process on FMUs reused as a worker reuses them
(median of --repeats batches of 10 runs, the first run left out), the wall time of --runs runs on
2 local workers (the benchmark's dispersion set: entry state, K and density), and the parallel
efficiency t1 / (2 t2) of --eff-runs runs on 1 and on 2 workers, whose rows must be identical.
Run it on an otherwise idle machine: the efficiency compares wall times.
"""

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "bench")]

from run import campaign_figures, cpu_ms_per_run  # noqa: E402

LAWS = ROOT / "scenarios" / "benchmark_seed000"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=1000, help="runs of the campaign on 2 workers")
    parser.add_argument("--eff-runs", type=int, default=200, help="runs of the 1- and 2-worker campaigns")
    parser.add_argument("--repeats", type=int, default=3, help="batches of 10 runs for the CPU per run")
    parser.add_argument("--laws", default="", help="comma-separated scenario names (default: every law)")
    args = parser.parse_args()
    chosen = [name for name in args.laws.split(",") if name]
    paths = [p for p in sorted(LAWS.glob("*.json")) if not chosen or p.stem in chosen]
    print(f"{'law':<20} {'CPU/run ms':>10} {f'{args.runs} runs s':>12} {'runs/s':>7} "
          f"{'eff. %':>6}  rows 1 = 2 workers  (targets: <= 15 ms, <= 10 s, >= 85 %)")
    for path in paths:
        per_run = cpu_ms_per_run(args.repeats, runs=10, scenario=path)
        _, _, same, eff, big = campaign_figures(path, args.runs, args.eff_runs)
        print(f"{path.stem:<20} {per_run:>10.1f} {big['wall_time_s']:>12.1f} {big['runs_per_s']:>7.1f} "
              f"{eff * 100:>6.0f}  {same}", flush=True)


if __name__ == "__main__":
    main()
