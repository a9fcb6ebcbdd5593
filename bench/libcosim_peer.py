"""The same system stepped by OSP libcosim (libcosimpy): the peer of target 2.

libcosim's fixed-step algorithm (Jacobi-like, every FMU steps from the same communication point)
with the same FMUs, parameters, connections and step, set up through libcosimpy's API. A
last-value observer records the latest values, as libcosim does by default. Bench only: the
product's SSP export is another module.
"""

import time

from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimObserver import CosimObserver
from libcosimpy.CosimSlave import CosimLocalSlave

NS = 1_000_000_000


def libcosim_execution(scenario):
    """A libcosim execution of the scenario's system: slaves, start values, connections."""
    system = scenario.system
    execution = CosimExecution.from_step_size(round(scenario.step * NS))
    index = {}
    for name, comp in system.components.items():
        index[name] = execution.add_local_slave(CosimLocalSlave(fmu_path=str(comp.fmu.path), instance_name=name))
        for var, value in comp.parameters.items():
            v = comp.fmu.variables[var]
            setter = execution.integer_initial_value if v.type == "Integer" else execution.real_initial_value
            setter(index[name], v.vr, int(value) if v.type == "Integer" else float(value))
    for c in system.connections:
        execution.connect_real_variables(index[c.source], system.variable(f"{c.source}.{c.output}").vr,
                                         index[c.target], system.variable(f"{c.target}.{c.input}").vr)
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    return execution, observer, index


def libcosim_us_per_step(scenario, clock=time.perf_counter):
    """Microseconds per communication step of libcosim on the scenario, set-up and FMU
    instantiation included as in the master's whole-run figure. clock: time.process_time counts
    the CPU of every libcosim thread."""
    t0 = clock()
    execution, observer, index = libcosim_execution(scenario)
    n = round((scenario.stop - scenario.start) / scenario.step)
    ok = execution.step(n)
    elapsed = clock() - t0
    assert ok, "libcosim failed to step"
    h = observer.last_real_values(index["vehicle"], [scenario.system.variable("vehicle.h").vr])[0]
    return elapsed / n * 1e6, h


def quiet():
    """Only libcosim's errors on the console (its default level prints every FMI call)."""
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level

    log_output_level(CosimLogLevel.ERROR)
