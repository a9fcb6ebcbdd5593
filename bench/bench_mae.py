"""Benchmark: wall time of one zeroth-order MAE guidance re-solve (seed 001, target < 50 ms).

    python bench/bench_mae.py [--repeats 7]

Flies the guided plane change once (reduced model, RK4 0.1 s, re-solves every 5 s, as in
tests/studies/test_seed001_mae.py) to record the measured state and the previous solution of each
re-solve, then repeats every warm-started re-solve `repeats` times. Prints the median over all
re-solves of the per-re-solve median, split into entry and exit phase, and the cold-start solve
from the entry state (App. B.1 guess) as the same-process baseline.
"""

import argparse
import math
import statistics
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # this checkout, not an installed copy
from aotv_cosim.guidance import mae
from aotv_cosim.guidance.mae_guided import MaeGuidanceLaw
from aotv_cosim.physics import mrrv, point_mass
from timing import median_seconds

MODEL = mae.MaeModel()
ENTRY = mae.State(MODEL.r_earth + 60.0e3, 7851.0, math.radians(-1.35), 0.0)
TARGETS = mae.Targets(60.0e3, math.radians(1.0), math.radians(20.0))
TARGET_S = 0.050


def _rates(x, lam, bank):
    """Reduced (3.1)-(3.6) (no tan(phi) term) via point_mass with phi held at 0."""
    cl, cd = mrrv.coefficients_per_mass(lam)
    dx = point_mass.derivatives([x[0], 0.0, 0.0, x[1], x[2], x[3]], mrrv.density(x[0] - MODEL.r_earth),
                                0.0, cl, cd, bank, point_mass.GRAVITY_INVERSE_SQUARE, 9.81, MODEL.mu_earth)
    return np.array([dx[0], dx[3], dx[4], dx[5]])


def guided_resolves(dt=0.1):
    """[(state, previous solution)] of every re-solve of one guided flight (x = r, v, gamma, psi)."""
    law = MaeGuidanceLaw(TARGETS, MODEL)
    x, t, cases = np.array([ENTRY.r, ENTRY.v, ENTRY.gamma, ENTRY.psi]), 0.0, []
    while not (x[2] > 0.0 and x[0] >= MODEL.r_earth + TARGETS.z_f):
        previous = law.solution
        if law.update(t, mae.State(*x)) and previous is not None:
            cases.append((mae.State(*x), previous))

        def rate(y):
            return _rates(y, *law.command(mae.State(*y)))
        k1 = rate(x)
        k2 = rate(x + 0.5 * dt * k1)
        k3 = rate(x + 0.5 * dt * k2)
        x = x + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + rate(x + dt * k3))
        t += dt
    return cases


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    cases = guided_resolves()
    per_case = {mae.ENTRY: [], mae.EXIT: []}
    for state, previous in cases:
        mode = mae.solve(state, TARGETS, previous).mode
        per_case[mode].append(median_seconds(lambda s=state, p=previous: mae.solve(s, TARGETS, p), args.repeats))
    every = per_case[mae.ENTRY] + per_case[mae.EXIT]
    cold = median_seconds(lambda: mae.solve(ENTRY, TARGETS), args.repeats)
    warm = statistics.median(every)
    print(f"MAE re-solves of one guided flight: {len(every)} "
          f"({len(per_case[mae.ENTRY])} entry, {len(per_case[mae.EXIT])} exit), {args.repeats} repeats each")
    for mode, values in per_case.items():
        print(f"  median {mode:5s} re-solve: {statistics.median(values) * 1e3:7.2f} ms "
              f"(max {max(values) * 1e3:.2f} ms)")
    print(f"  median re-solve         : {warm * 1e3:7.2f} ms  (target < {TARGET_S * 1e3:.0f} ms: "
          f"{'met' if warm < TARGET_S else 'NOT met'})")
    print(f"  cold solve from entry   : {cold * 1e3:7.2f} ms  (re-solve / cold = {warm / cold:.2f})")


if __name__ == "__main__":
    main()
