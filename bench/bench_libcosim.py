"""Benchmark: OSP libcosim's wall time per communication step on the 4-FMU seed-000 system,
exported as SSP, against this master (Jacobi, libcosim's scheme, and Gauss-Seidel) in the same
process, 0.1 s step, 300 s (3000 steps).

    python bench/bench_libcosim.py [--repeats 5]

Prints medians of several runs. libcosim's time counts its stepping only (loading the SSP and
instantiating the FMUs excluded), like the master's (initialization excluded). libcosim steps
the components in parallel worker threads; the FMUs are Python (pythonfmu), so the GIL
serializes their do_step bodies.
"""

import argparse
import statistics
import tempfile
from pathlib import Path

from aotv_cosim.engine.master import Master
from aotv_cosim.engine.scenario import load_scenario
from aotv_cosim.ssp import libcosim_run
from aotv_cosim.ssp.export import export_ssp

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "aotv_time_linear_nominal.json"


def libcosim_us_per_step(ssp, scenario):
    steps = round((scenario.stop - scenario.start) / scenario.step)
    result = libcosim_run.run(ssp, scenario.stop, ["vehicle.h"], log_level="ERROR")
    return result["steps_wall_s"] / steps * 1e6


def master_us_per_step(scenario, algorithm):
    scenario.algorithm = algorithm
    outcome = Master(scenario, lambda times, rows: None).run()
    assert outcome.status == "completed", outcome.error
    return (outcome.wall_time - outcome.init_time) / outcome.steps * 1e6


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    scenario = load_scenario(SCENARIO, step=0.1)
    scenario.stop_conditions = []
    with tempfile.TemporaryDirectory() as tmp:
        ssp = export_ssp(scenario, Path(tmp) / "nominal.ssp")
        timings = {"libcosim": [libcosim_us_per_step(ssp, scenario) for _ in range(args.repeats)]}
    for algorithm in ("jacobi", "gauss-seidel"):
        timings[f"master {algorithm}"] = [master_us_per_step(scenario, algorithm) for _ in range(args.repeats)]
    medians = {name: statistics.median(values) for name, values in timings.items()}
    for name, value in medians.items():
        print(f"{name:<22} {value:8.1f} us/step (median of {args.repeats})")
    print(f"libcosim / master jacobi: {medians['libcosim'] / medians['master jacobi']:.2f}")


if __name__ == "__main__":
    main()
