"""Cost against accuracy: fixed communication steps (held and extrapolated inputs) and
error-controlled steps (step doubling, `simulation.step_doubling`), on two cases.

    python bench/bench_step_control.py [--case nominal|entry|both] [--repeat N]

- nominal: seed-000 nominal pass (aotv_time_linear_nominal.json), error = |h(tf) - h_ref(tf)|,
  h_ref from the monolithic SciPy reference (rtol 1e-12).
- entry: seed-002 3-D entry tracked to the terminal energy (entry_full_nominal.json), error =
  |downrange at the located terminal-energy event - its value with a 0.005 s extrapolated step|
  (self-convergence: the FMUs' own equations, no monolithic reference of the tracking law).

Cost is the CPU time of the whole run (this process, instantiation included; median of
--repeat runs) and the number of sweeps (one sweep steps every FMU once; with a tolerance, every
sweep made: attempts, rejected steps, coarse runs). Each error-controlled line is run with the
local check and with the global one (`simulation.step_doubling`), and compared with the best fixed step of
the same error: the two extrapolated fixed steps whose errors bracket it are run again right
after it, and their CPU interpolated in log(error)-log(CPU) (blank outside the curve); the
ratio is the median over --repeat such rounds, so it does not drift with the machine's speed
over the minutes the bench takes.
"""

import argparse
import itertools
import json
import math
import statistics
import sys
import tempfile
import time
from pathlib import Path
from types import SimpleNamespace

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT)]

from aotv_cosim.simulation.master import Master  # noqa: E402
from aotv_cosim.simulation.loading import load_scenario  # noqa: E402
from aotv_cosim.studies.reference import reference_run  # noqa: E402

CASES = {
    "nominal": (ROOT / "scenarios" / "aotv_time_linear_nominal.json", "vehicle.h", "end",
                [0.05, 0.1, 0.25, 0.5, 1.0, 2.0], [10.0, 1.0, 0.1, 0.01]),
    "entry": (ROOT / "scenarios" / "entry_full_nominal.json", "vehicle.downrange", "event",
              [0.02, 0.05, 0.1, 0.25, 0.5, 1.0], [100.0, 10.0, 1.0, 0.1]),
}


def variant(source, step, folder):
    doc = json.loads(source.read_text())
    doc.update(system=str(source.parent / doc["system"]), step=step, expectations=[], plots=[])
    path = Path(folder) / f"case{abs(hash(json.dumps(step, sort_keys=True)))}.json"
    path.write_text(json.dumps(doc))
    return load_scenario(path)


def measure(scenario, signal, at, repeat=1):
    """(value of signal at the end or at the event, median CPU s of the whole run, outcome)."""
    cpus = []
    for _ in range(repeat):
        last = {}
        cpu0 = time.process_time()
        master = Master(scenario)
        outcome = master.run(SimpleNamespace(record=lambda times, rows, last=last: last.update(row=rows[-1])))
        cpus.append(time.process_time() - cpu0)
        assert outcome.status == "completed", outcome.error
    value = outcome.event["values"][signal] if at == "event" else float(last["row"][master.index[signal]])
    return value, statistics.median(cpus), outcome


def cpu_of(scenario):
    """CPU s of one whole run of `scenario` in this process."""
    cpu0 = time.process_time()
    Master(scenario).run(SimpleNamespace(record=lambda times, rows: None))
    return time.process_time() - cpu0


def interpolated(error, bracket):
    """CPU at `error` along the log-log line through [(error, CPU), (error, CPU)]."""
    (e0, c0), (e1, c1) = bracket
    w = math.log(error / e0) / math.log(e1 / e0) if e1 > e0 else 0.0
    return math.exp(math.log(c0) + w * math.log(c1 / c0))


def against_fixed(scenario, error, first_cpu, fixed, repeat):
    """(median CPU s of `scenario`, median of its CPU / that of a fixed step of the same `error`)
    over `repeat` rounds, the first one's run already made (`first_cpu`). The fixed step's CPU
    is interpolated between the two runs of `fixed` [(error, scenario)] whose errors bracket
    `error`, made in the same round; the ratio is None outside the curve."""
    points = sorted(fixed, key=lambda p: p[0])
    pairs = [(a, b) for a, b in itertools.pairwise(points) if a[0] <= error <= b[0] and a[0] > 0]
    cpus, ratios = [], []
    for k in range(repeat):
        cpus.append(cpu_of(scenario) if k else first_cpu)
        if pairs:
            (e0, s0), (e1, s1) = pairs[0]
            ratios.append(cpus[-1] / interpolated(error, [(e0, cpu_of(s0)), (e1, cpu_of(s1))]))
    return statistics.median(cpus), statistics.median(ratios) if ratios else None


def curve(name, folder, repeat):
    source, signal, at, steps, tolerances = CASES[name]
    if name == "nominal":
        ref = reference_run(load_scenario(source)).final[signal]
    else:
        ref = measure(variant(source, {"size": 0.005, "inputs": "extrapolated"}, folder), signal, at)[0]
    print(f"\n{name}: error of {signal} ({at}) against the reference; median CPU s of {repeat} whole runs")
    print(f"  {'stepping':<36} {'error':>11} {'CPU s':>8} {'sweeps':>7} {'estimate':>10} {'x best fixed':>12}")
    extrapolated = []
    for inputs in ("held", "extrapolated"):
        for h in steps:
            scenario = variant(source, {"size": h, "inputs": inputs}, folder)
            value, cpu, outcome = measure(scenario, signal, at, repeat)
            if inputs == "extrapolated":
                extrapolated.append((abs(value - ref), scenario))
            print(f"  {f'fixed {h:g} s, {inputs}':<36} {abs(value - ref):>11.4g} {cpu:>8.3f} {outcome.steps:>7}")
    for tol in tolerances:
        for check in ("local", "global"):
            step = {"size": 0.5, "tolerance": {signal: tol}, "check": check}
            scenario = variant(source, step, folder)
            value, cpu, outcome = measure(scenario, signal, at)
            stats, error = outcome.step_control, abs(value - ref)
            estimate = stats.get("global_error", {}).get(signal)
            cpu, fixed = against_fixed(scenario, error, cpu, extrapolated, repeat)
            label = f"tolerance {tol:g}, {check}" + (f" ({stats['attempts']} att.)" if check == "global" else "")
            print(f"  {label:<36} {error:>11.4g} {cpu:>8.3f} {stats['sweeps']:>7} "
                  f"{'' if estimate is None else f'{estimate:.4g}':>10} {'' if fixed is None else f'{fixed:.2f}':>12}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", choices=["nominal", "entry", "both"], default="both")
    parser.add_argument("--repeat", type=int, default=3, help="runs per line, CPU median (default 3)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        for name in (["nominal", "entry"] if args.case == "both" else [args.case]):
            curve(name, folder, args.repeat)


if __name__ == "__main__":
    main()
