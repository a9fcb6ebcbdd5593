"""Benchmark: the whole communication step of the master on the default scenario
(scenarios/aotv_time_linear_nominal.json, 4 FMUs, 0.1 s step, 3000 steps) with each way of
calling the FMUs: through pythonfmu's own C wrapper (stock), through this package's lean C
wrapper (lean), and the lean-built FMUs' slaves called directly in this interpreter (direct).

    nice -n 5 python bench/bench_fmi_calls.py [--repeats 7]

Runs of the three alternate in one process; per run the stepping loop's CPU time per step
(time.thread_time_ns, FMU work included) and its wall time; medians and their ratios.
"""

import argparse
from types import SimpleNamespace
import statistics
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT), str(ROOT / "bench")]

from timing import CpuTimedMaster  # noqa: E402
from aotv_cosim.simulation.loading import load_scenario  # noqa: E402
from bench_libcosim import with_wrapper  # noqa: E402

NOMINAL = ROOT / "scenarios" / "aotv_time_linear_nominal.json"
WAYS = ("stock", "lean", "direct")


def one_run(scenario, calls):
    """(CPU us per step, wall us per step) of the stepping loop of one run."""
    master = CpuTimedMaster(scenario, fmi_calls=calls)
    outcome = master.run(SimpleNamespace(record=lambda times, rows: None))
    assert outcome.status == "completed", outcome.error
    return master.loop_cpu_ns / outcome.steps / 1e3, outcome.loop_time / outcome.steps * 1e6


def measure(repeats: int) -> dict:
    """{way: {"cpu": median us/step, "wall": median us/step}} over `repeats` interleaved rounds."""
    scenarios = {"stock": with_wrapper("stock", load_scenario, NOMINAL),
                 "lean": with_wrapper("lean", load_scenario, NOMINAL)}
    ways = {"stock": (scenarios["stock"], "c"), "lean": (scenarios["lean"], "c"),
            "direct": (scenarios["lean"], "direct")}
    for scenario, calls in ways.values():  # warm-up: extraction, imports
        one_run(scenario, calls)
    samples = {way: {"cpu": [], "wall": []} for way in WAYS}
    for k in range(repeats):
        for way in WAYS[k % 3:] + WAYS[:k % 3]:  # each way first in turn
            cpu, wall = one_run(*ways[way])
            samples[way]["cpu"].append(cpu)
            samples[way]["wall"].append(wall)
    return {way: {kind: statistics.median(v) for kind, v in by.items()} for way, by in samples.items()}


def ratios(med: dict, kind: str = "cpu") -> dict:
    """direct / stock, direct / lean and lean / stock of the medians `med` (`measure`)."""
    return {"direct / stock": med["direct"][kind] / med["stock"][kind],
            "direct / lean": med["direct"][kind] / med["lean"][kind],
            "lean / stock": med["lean"][kind] / med["stock"][kind]}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    med = measure(args.repeats)
    print(f"{NOMINAL.name}: whole communication step, median of {args.repeats} interleaved runs")
    for way in WAYS:
        print(f"  {way:<7} CPU {med[way]['cpu']:6.1f} us/step   wall {med[way]['wall']:6.1f} us/step")
    for kind in ("cpu", "wall"):
        print(f"  {kind}: " + ", ".join(f"{name} {value:.3f}" for name, value in ratios(med, kind).items()))


if __name__ == "__main__":
    main()
