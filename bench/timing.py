"""Timing helper shared by the benchmarks: medians of repeated calls, on a clock of choice."""

import statistics
import time


def median_seconds(call, repeats, clock=time.perf_counter):
    """Median duration (s) of `repeats` calls of call(), measured by `clock` (wall time by
    default; time.process_time for CPU time on a shared machine)."""
    samples = []
    for _ in range(repeats):
        start = clock()
        call()
        samples.append(clock() - start)
    return statistics.median(samples)
