"""Cost against accuracy: fixed communication steps (held and extrapolated inputs) and
error-controlled steps (step doubling, `engine.adaptive`), on two cases (issue 17 item 4).

    python bench/bench_step_control.py [--case nominal|entry|both]

- nominal: seed-000 nominal pass (aotv_time_linear_nominal.json), error = |h(tf) - h_ref(tf)|,
  h_ref from the monolithic SciPy reference (rtol 1e-12).
- entry: seed-002 3-D entry tracked to the terminal energy (entry_full_nominal.json), error =
  |downrange at the located terminal-energy event - its value with a 0.005 s extrapolated step|
  (self-convergence: the FMUs' own equations, no monolithic reference of the tracking law).

Cost is the CPU time of the whole run (this process, instantiation included) and the number of
sweeps (one sweep steps every FMU once). Each line: one run; the table is the curve.
"""

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT)]

from aotv_cosim.engine.master import Master  # noqa: E402
from aotv_cosim.engine.scenario import load_scenario  # noqa: E402
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


def measure(scenario, signal, at):
    """(value of signal at the end or at the event, CPU s of the whole run, sweeps)."""
    last = {}
    cpu0 = time.process_time()
    master = Master(scenario, lambda times, rows: last.update(row=rows[-1]))
    outcome = master.run()
    cpu = time.process_time() - cpu0
    assert outcome.status == "completed", outcome.error
    value = outcome.event["values"][signal] if at == "event" else float(last["row"][master.index[signal]])
    sweeps = outcome.step_control["sweeps"] if outcome.step_control else outcome.steps
    return value, cpu, sweeps


def curve(name, folder):
    source, signal, at, steps, tolerances = CASES[name]
    if name == "nominal":
        ref = reference_run(load_scenario(source)).final[signal]
    else:
        ref = measure(variant(source, {"size": 0.005, "inputs": "extrapolated"}, folder), signal, at)[0]
    print(f"\n{name}: error of {signal} ({at}) against the reference; CPU s of the whole run")
    print(f"  {'stepping':<44} {'error':>12} {'CPU s':>8} {'sweeps':>8}")
    for inputs in ("held", "extrapolated"):
        for h in steps:
            value, cpu, sweeps = measure(variant(source, {"size": h, "inputs": inputs}, folder), signal, at)
            print(f"  {f'fixed {h:g} s, {inputs}':<44} {abs(value - ref):>12.4g} {cpu:>8.3f} {sweeps:>8}")
    for tol in tolerances:
        step = {"size": 0.5, "tolerance": {signal: tol}}
        value, cpu, sweeps = measure(variant(source, step, folder), signal, at)
        print(f"  {f'tolerance {tol:g} (extrapolated)':<44} {abs(value - ref):>12.4g} {cpu:>8.3f} {sweeps:>8}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", choices=["nominal", "entry", "both"], default="both")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        for name in (["nominal", "entry"] if args.case == "both" else [args.case]):
            curve(name, folder)


if __name__ == "__main__":
    main()
