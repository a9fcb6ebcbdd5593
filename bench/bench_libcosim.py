"""Benchmark: the FMUs' lean FMI wrapper against pythonfmu's own (stock), in this master and in
OSP libcosim, on the 4-FMU seed-000 system (aotv_time_linear_nominal) exported as SSP, 0.1 s
step, 300 s (3000 steps).

    python bench/bench_libcosim.py [--repeats 7]

Both FMU sets are built (AOTV_COSIM_WRAPPER=stock and =lean, aotv_cosim.fmu.native) and run in
one process, the four variants (master or libcosim, stock or lean) interleaved in each round, in
an order that rotates between rounds. Per communication step, medians over the rounds:
- master: CPU time of its stepping loop (one thread; initialization excluded) and wall time;
- libcosim: CPU time of the whole process while it steps (its worker threads included; loading
  the SSP and instantiating excluded) and wall time. libcosim steps the components in parallel
  worker threads, which the FMUs' Python serializes on the GIL.
Then the ratios: libcosim stock / lean (how much faster libcosim steps the lean FMUs), master
lean / stock, master / libcosim for each wrapper, and this master as shipped (lean FMUs) /
libcosim with pythonfmu's FMUs. The final values of every state output
must be the same to the bit with either wrapper, in the master and in libcosim (else it stops).
"""

import argparse
import os
import platform
import statistics
import tempfile
import time
from pathlib import Path
from types import SimpleNamespace

from timing import CpuTimedMaster
from aotv_cosim.simulation.loading import load_scenario
from aotv_cosim.fmu import native
from aotv_cosim.ssp.export import export_ssp

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "aotv_time_linear_nominal.json"
WRAPPERS = ("stock", "lean")


def with_wrapper(wrapper, function, *args, **kwargs):
    """function(*args, **kwargs) with AOTV_COSIM_WRAPPER=wrapper (FMUs built or found for it)."""
    saved = os.environ.get(native.WRAPPER_VARIABLE)
    os.environ[native.WRAPPER_VARIABLE] = wrapper
    try:
        return function(*args, **kwargs)
    finally:
        if saved is None:
            del os.environ[native.WRAPPER_VARIABLE]
        else:
            os.environ[native.WRAPPER_VARIABLE] = saved


def prepared(wrapper, folder):
    """(scenario, exported SSP) of the benchmark system with the FMUs of `wrapper`."""
    scenario = with_wrapper(wrapper, load_scenario, SCENARIO, step=0.1)
    scenario.stop_conditions = []
    ssp = with_wrapper(wrapper, export_ssp, scenario, Path(folder) / f"{wrapper}.ssp")
    return scenario, ssp


def master_step(scenario):
    """({"cpu": us, "wall": us} per step, final values of the state outputs) of one master run."""
    last = []
    # through the FMUs' C wrappers: the lean and stock FMUs differ only there
    master = CpuTimedMaster(scenario, fmi_calls="c")
    outcome = master.run(SimpleNamespace(record=lambda times, rows: last.append(rows[-1])))
    assert outcome.status == "completed", outcome.error
    states = state_outputs(scenario)
    final = {s: last[-1][i] for s, i in master.index.items() if s in states}
    return {"cpu": master.loop_cpu_ns / outcome.steps / 1e3, "wall": outcome.loop_time / outcome.steps * 1e6}, final


def state_outputs(scenario):
    """component.output for every output without direct feedthrough (libcosim's observer and this
    master read them at the same instant) and that is not a wall-clock measurement."""
    return {f"{c.name}.{o}" for c in scenario.system.components.values()
            for o, deps in c.fmu.feedthrough.items() if not deps and o != "solve_time"}


def libcosim_step(ssp, scenario):
    """({"cpu": us, "wall": us} per step, final values of the state outputs) of one libcosim run."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)
    execution = CosimExecution.from_ssp_file(str(ssp))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    index = {info.name.decode(): info.index for info in execution.slave_infos()}
    refs = {n: {v.name.decode(): v.reference for v in execution.slave_variables(i)} for n, i in index.items()}
    steps = round((scenario.stop - scenario.start) / scenario.step)
    cpu0, wall0 = time.process_time_ns(), time.perf_counter_ns()
    assert execution.simulate_until(round(scenario.stop * 1e9)), "libcosim failed"
    cpu, wall = time.process_time_ns() - cpu0, time.perf_counter_ns() - wall0
    final = {}
    for signal in state_outputs(scenario):
        comp, var = signal.split(".", 1)
        final[signal] = observer.last_real_values(index[comp], [refs[comp][var]])[0]
    return {"cpu": cpu / steps / 1e3, "wall": wall / steps / 1e3}, final


def measure(repeats):
    """{(engine, wrapper): {"cpu": us, "wall": us}} per step, medians of `repeats` interleaved
    rounds after a warm-up round; stops unless lean and stock give the same final values."""
    timings = {(engine, w): {"cpu": [], "wall": []} for engine in ("master", "libcosim") for w in WRAPPERS}
    finals = {}
    with tempfile.TemporaryDirectory() as tmp:
        systems = {w: prepared(w, tmp) for w in WRAPPERS}
        runs = list(timings)
        for k in range(repeats + 1):  # round 0 warms up (imports, extraction) and is not counted
            for engine, w in runs[k % len(runs):] + runs[:k % len(runs)]:
                scenario, ssp = systems[w]
                step, final = master_step(scenario) if engine == "master" else libcosim_step(ssp, scenario)
                if k:
                    for key in step:
                        timings[engine, w][key].append(step[key])
                finals.setdefault(engine, {}).setdefault(w, final)
    for engine in ("master", "libcosim"):
        assert finals[engine]["lean"] == finals[engine]["stock"], (engine, finals[engine])
        print(f"  {engine}: final values of {len(finals[engine]['lean'])} state outputs identical with "
              f"the lean and the stock wrapper")
    return {key: {k: statistics.median(v) for k, v in values.items()} for key, values in timings.items()}


def ratios(med, clock):
    """{name: ratio} of the `measure` medians on `clock` ("cpu" or "wall")."""
    out = {"libcosim stock / lean": med["libcosim", "stock"][clock] / med["libcosim", "lean"][clock],
           "master lean / stock": med["master", "lean"][clock] / med["master", "stock"][clock]}
    for w in WRAPPERS:
        out[f"master / libcosim, {w} FMUs"] = med["master", w][clock] / med["libcosim", w][clock]
    out["master lean / libcosim stock"] = med["master", "lean"][clock] / med["libcosim", "stock"][clock]
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, "
          f"Python {platform.python_version()}, load average {os.getloadavg()[0]:.1f}")
    med = measure(args.repeats)
    for (engine, w), values in med.items():
        print(f"{engine:<9} {w:<6} CPU {values['cpu']:8.1f} us/step   wall {values['wall']:8.1f} us/step"
              f"   (medians of {args.repeats})")
    for clock in ("cpu", "wall"):
        print(f"ratios, {clock}:")
        for name, value in ratios(med, clock).items():
            print(f"  {name:<30} {value:6.3f}" + ("   (target >= 3)" if name.startswith("libcosim") else ""))


if __name__ == "__main__":
    main()
