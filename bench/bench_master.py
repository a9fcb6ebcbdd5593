"""Benchmark: master cost per communication step on the 4-FMU seed-000 system, against a naive
FMPy loop over the same FMUs in the same process, and the wall time of the monolithic reference.

    python bench/bench_master.py [--repeats 7]

Prints medians of several runs and the ratio master / naive loop. The naive loop is what a first
FMPy script does: per connection a getReal and a setReal through FMPy's wrappers, then doStep on
every FMU, recording the same signals.
"""

import argparse
import statistics
import time
from pathlib import Path
from types import SimpleNamespace

from fmpy.fmi2 import FMU2Slave

from aotv_cosim.simulation import ordering
from aotv_cosim.simulation.unpacked import extracted
from aotv_cosim.simulation.master import Master
from aotv_cosim.studies.reference import reference_run
from aotv_cosim.output.runner import recorded_columns
from aotv_cosim.simulation.loading import load_scenario

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "aotv_time_linear_nominal.json"


def master_us_per_step(scenario):
    """Microseconds per communication step of the master loop (initialization excluded)."""
    outcome = Master(scenario).run(SimpleNamespace(record=lambda times, rows: None))
    assert outcome.status == "completed", outcome.error
    return (outcome.wall_time - outcome.init_time) / outcome.steps * 1e6


def naive_us_per_step(scenario, clock=time.perf_counter):
    """The same system stepped by a plain FMPy loop (getReal/setReal per connection).

    clock: the clock of the timing (time.thread_time for CPU time)."""
    system = scenario.system
    slaves = {}
    for name, comp in system.components.items():
        md = comp.fmu.model_description
        slave = FMU2Slave(guid=md.guid, unzipDirectory=str(extracted(comp.fmu.path)),
                          modelIdentifier=comp.fmu.model_identifier, instanceName=name)
        slave.instantiate()
        slave.setupExperiment(startTime=scenario.start)
        for var, value in comp.parameters.items():
            v = comp.fmu.variables[var]
            (slave.setInteger if v.type == "Integer" else slave.setReal)([v.vr], [value])
        slave.enterInitializationMode()
        slaves[name] = slave
    links = [(slaves[c.source], system.variable(f"{c.source}.{c.output}").vr,
              slaves[c.target], system.variable(f"{c.target}.{c.input}").vr) for c in system.connections]
    for src, ovr, dst, ivr in links + links:  # twice: let feedthrough chains settle
        dst.setReal([ivr], src.getReal([ovr]))
    for slave in slaves.values():
        slave.exitInitializationMode()
    order = [slaves[n] for n in ordering.gauss_seidel_order(system)]
    recorded = [(slaves[s.split(".")[0]], system.variable(s).vr) for s in recorded_columns(scenario)]
    n = round((scenario.stop - scenario.start) / scenario.step)
    rows = []
    t0 = clock()
    for k in range(n):
        t = scenario.start + k * scenario.step
        for src, ovr, dst, ivr in links:
            dst.setReal([ivr], src.getReal([ovr]))
        for slave in order:
            slave.doStep(currentCommunicationPoint=t, communicationStepSize=scenario.step)
        rows.append([slave.getReal([vr])[0] for slave, vr in recorded])
    elapsed = clock() - t0
    for slave in slaves.values():
        slave.terminate()
        slave.freeInstance()
    return elapsed / n * 1e6


def reference_wall(scenario):
    t0 = time.perf_counter()
    reference_run(scenario)
    return time.perf_counter() - t0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    scenario = load_scenario(SCENARIO)
    master_us_per_step(scenario)  # warm-up: extraction, imports
    master, naive, reference = [], [], []
    for _ in range(args.repeats):
        master.append(master_us_per_step(scenario))
        naive.append(naive_us_per_step(scenario))
        reference.append(reference_wall(scenario))
    m, nv = statistics.median(master), statistics.median(naive)
    print(f"system: {SCENARIO.name}, 4 FMUs, step {scenario.step} s, "
          f"{round((scenario.stop - scenario.start) / scenario.step)} steps, "
          f"{len(recorded_columns(scenario))} signals recorded, median of {args.repeats} runs")
    print(f"master            : {m:7.1f} us/step  (whole step, FMU work included)")
    print(f"naive FMPy loop   : {nv:7.1f} us/step")
    print(f"ratio master/naive: {m / nv:7.2f}")
    print(f"monolithic reference (solve_ivp DOP853, rtol 1e-12): {statistics.median(reference) * 1e3:.1f} ms")


if __name__ == "__main__":
    main()
