"""Whole step of the default scenario, this tree against another checkout, alternated.

    python bench/bench_against_tree.py OTHER_TREE [--cache DIR] [--rounds 9] [--scenario FILE] [--fmi-calls c|direct]

Each round runs one process in OTHER_TREE (PYTHONPATH set to it; FMU cache `--cache`, else this one's)
and one in this tree, each timing the stepping loop's thread CPU of 7 runs after a warm-up run
and printing the median per step; the rounds alternate the two trees so the machine's drift
falls on both. Prints each round and the ratio of the medians (this tree / the other). The
step script works with the master of either layout (`simulation.master`, `engine.master`, or the
flat `aotv_cosim.master` of the earlier trees).
"""

import argparse
import os
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

STEP = r'''
import statistics, sys, time
from types import SimpleNamespace
try:
    from aotv_cosim.simulation.loading import load_scenario
    from aotv_cosim.simulation.master import Master
    RECORDER = True
except ImportError:
    RECORDER = False
    try:
        from aotv_cosim.engine.scenario import load_scenario
        from aotv_cosim.engine.master import Master
    except ImportError:
        from aotv_cosim.scenario import load_scenario
        from aotv_cosim.master import Master


class Timed(Master):
    def _loop(self, rows, outcome):
        t0 = time.thread_time_ns()
        try:
            super()._loop(rows, outcome)
        finally:
            self.cpu = time.thread_time_ns() - t0


scenario = load_scenario(sys.argv[1])
calls = {"fmi_calls": sys.argv[2]} if len(sys.argv) > 2 else {}
samples = []
for k in range(8):
    if RECORDER:
        master = Timed(scenario, **calls)
        outcome = master.run(SimpleNamespace(record=lambda t, r: None))
    else:
        master = Timed(scenario, lambda t, r: None)
        outcome = master.run()
    assert outcome.status == "completed", outcome.error
    if k:
        samples.append(master.cpu / outcome.steps / 1e3)
print(statistics.median(samples))
'''


def us_per_step(tree: Path, cache, scenario: Path, fmi_calls=None) -> float:
    """Median CPU per communication step (us) of the stepping loop, in a process of `tree` whose
    FMU cache is `cache` (None: this process's), the FMUs called as `fmi_calls` says (None: the
    master's default)."""
    env = dict(os.environ, PYTHONPATH=str(tree), OPENBLAS_NUM_THREADS="1")
    if cache is not None:
        env["AOTV_COSIM_CACHE"] = str(cache)
    done = subprocess.run([sys.executable, "-c", STEP, str(scenario)] + ([fmi_calls] if fmi_calls else []),
                          cwd=tree, env=env, check=True, capture_output=True, text=True)
    return float(done.stdout.split()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("other", type=Path, help="the other checkout (a git worktree)")
    parser.add_argument("--cache", type=Path, help="its FMU cache [the same as this tree's]")
    parser.add_argument("--rounds", type=int, default=9)
    parser.add_argument("--scenario", type=Path, default=ROOT / "scenarios" / "aotv_time_linear_nominal.json")
    parser.add_argument("--fmi-calls", choices=("c", "direct"), help="how both masters call the FMUs [their default]")
    args = parser.parse_args()
    other, cache = args.other.resolve(), args.cache.resolve() if args.cache else None
    theirs, ours = [], []
    for k in range(args.rounds):
        theirs.append(us_per_step(other, cache, args.scenario.resolve(), args.fmi_calls))
        ours.append(us_per_step(ROOT, None, args.scenario.resolve(), args.fmi_calls))
        print(f"round {k + 1}: other {theirs[-1]:.2f} us/step, this tree {ours[-1]:.2f} us/step")
    a, b = statistics.median(theirs), statistics.median(ours)
    print(f"medians: other {a:.2f}, this tree {b:.2f} us/step; this tree / other {b / a:.3f}")


if __name__ == "__main__":
    main()
