"""Timing helper shared by the benchmarks: medians of repeated calls, on a clock of choice."""

import statistics
import time

from aotv_cosim.simulation.master import Master


def median_seconds(call, repeats, clock=time.perf_counter):
    """Median duration (s) of `repeats` calls of call(), measured by `clock` (wall time by
    default; time.process_time for CPU time on a shared machine)."""
    samples = []
    for _ in range(repeats):
        start = clock()
        call()
        samples.append(clock() - start)
    return statistics.median(samples)


def machine() -> str:
    """The machine a bench runs on, for its first line: CPU model (/proc/cpuinfo, else the
    platform's name), cores, Python version and the 1-minute load average now (timings from a
    machine whose load average exceeds its cores are inflated by other work)."""
    import os
    import platform

    model = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as info:
            model = next((line.split(":", 1)[1].strip() for line in info if line.startswith("model name")),
                         model)
    except OSError:
        pass
    return (f"{model}, {os.cpu_count()} cores, Python {platform.python_version()}, "
            f"load average {os.getloadavg()[0]:.2f} at the start")


class CpuTimedMaster(Master):
    """The master with the CPU time of its stepping loop measured (`loop_cpu_ns`)."""

    def _loop(self, rows, outcome):
        t0 = time.thread_time_ns()
        try:
            super()._loop(rows, outcome)
        finally:
            self.loop_cpu_ns = time.thread_time_ns() - t0
