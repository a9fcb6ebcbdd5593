"""Benchmark: the master's CPU per communication step with the FMUs of this tree against the same
system's FMUs built from another source tree (e.g. the main checkout), in one process, alternated.

    python bench/bench_fmu_versions.py SCENARIO --base-tree /path/to/other/checkout
                                       [--base-cache DIR] [--rounds 9] [--runs 3]

The other tree builds its FMUs in a subprocess (its own `aotv_cosim.fmu.build.ensure_fmu`, cache
--base-cache, default that tree's own default); every FMU carries its runtime under a name of its
own, so both versions load side by side here and run under this tree's master. Each round runs
the scenario --runs times with each version in turn; the figure is the CPU time of the master's
stepping loop (one thread) per step, median over all runs, and the ratio this tree / base. On a
machine shared with other work, absolute times move with the load; the ratio, taken from runs
interleaved within seconds, much less.
"""

import argparse
from types import SimpleNamespace
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from timing import CpuTimedMaster  # noqa: E402
from aotv_cosim.simulation.loading import load_scenario  # noqa: E402
from aotv_cosim.fmu.build import ensure_fmu  # noqa: E402

BUILD = "import sys; from aotv_cosim.fmu.build import ensure_fmu; print(*(ensure_fmu(n) for n in sys.argv[1:]))"
"""Run in the other tree: build (or find in its cache) the named FMUs and print their paths."""


def base_fmus(names, tree: Path, cache) -> dict:
    """{name: .fmu path} of the FMUs `names` built from the sources of `tree`."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    env.pop("AOTV_COSIM_CACHE", None)
    if cache:
        env["AOTV_COSIM_CACHE"] = str(cache)
    out = subprocess.run([sys.executable, "-c", BUILD, *names], env=env, cwd=tree, check=True,
                         capture_output=True, text=True).stdout.split()
    return dict(zip(names, out))


def with_fmus(scenario_path: Path, fmus: dict, folder: Path, tag: str):
    """The scenario with its wiring's FMU names replaced by the .fmu files `fmus` {name: path}."""
    doc = json.loads(scenario_path.read_text())
    wiring = json.loads((scenario_path.parent / doc["system"]).read_text())
    for comp in wiring["components"].values():
        comp["fmu"] = str(fmus[comp["fmu"]])
    for key, value in list(doc.items()):  # other relative paths of the scenario, made absolute
        if isinstance(value, str) and value.endswith(".json") and key != "$schema":
            doc[key] = str((scenario_path.parent / value).resolve())
    (folder / f"{tag}_wiring.json").write_text(json.dumps(wiring))
    doc["system"] = str(folder / f"{tag}_wiring.json")
    doc.pop("$schema", None)
    wiring.pop("$schema", None)
    (folder / f"{tag}.json").write_text(json.dumps(doc))
    return load_scenario(folder / f"{tag}.json")


def us_per_step(scenario) -> float:
    master = CpuTimedMaster(scenario)
    outcome = master.run(SimpleNamespace(record=lambda times, rows: None))
    assert outcome.status == "completed", outcome.error
    return master.loop_cpu_ns / outcome.steps / 1e3


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario", type=Path)
    parser.add_argument("--base-tree", type=Path, required=True, help="source checkout of the base FMUs")
    parser.add_argument("--base-cache", type=Path, help="FMU cache of the base tree's builds")
    parser.add_argument("--rounds", type=int, default=9)
    parser.add_argument("--runs", type=int, default=3, help="runs of each version per round")
    args = parser.parse_args()
    wiring = json.loads((args.scenario.parent / json.loads(args.scenario.read_text())["system"]).read_text())
    names = sorted({comp["fmu"] for comp in wiring["components"].values()})
    versions = {"base": base_fmus(names, args.base_tree.resolve(), args.base_cache),
                "this tree": {n: ensure_fmu(n) for n in names}}
    with tempfile.TemporaryDirectory() as tmp:
        scenarios = {tag: with_fmus(args.scenario.resolve(), fmus, Path(tmp), tag.replace(" ", "_"))
                     for tag, fmus in versions.items()}
        times = {tag: [] for tag in scenarios}
        for scenario in scenarios.values():
            us_per_step(scenario)  # warm-up: extraction, imports
        for _ in range(args.rounds):
            for tag, scenario in scenarios.items():
                times[tag] += [us_per_step(scenario) for _ in range(args.runs)]
    base, this = statistics.median(times["base"]), statistics.median(times["this tree"])
    print(f"{args.scenario.name}: base {base:.2f} us/step, this tree {this:.2f} us/step, ratio this / base "
          f"{this / base:.3f} (master loop CPU, medians of {args.rounds} rounds x {args.runs} runs, alternated; "
          f"load average {os.getloadavg()[0]:.1f})")


if __name__ == "__main__":
    main()
