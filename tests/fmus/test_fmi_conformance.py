"""Every FMU of fmus_src is right under the call orders FMI 2.0 allows, driven through FMPy's
low-level FMU2Slave.

The reference order is this package's master's: parameters and start values set before
fmi2EnterInitializationMode. Each other order must give the same outputs to the bit, read in
initialization mode (after the last set), after fmi2ExitInitializationMode and after each of a few
steps:

- `after`: every value set after fmi2EnterInitializationMode (what Ecos does);
- `passes`: outputs read on the start values, then a second value set B, then the values A twice,
  outputs read after each set (a host's repeated initialization passes); an expensive solve is made
  once per distinct value set: its `solve_time` does not change over the repeated set of A, nor
  when initialization ends;
- `reset`: a run with B, fmi2Reset, then A;
- `state`: A set, the state saved in initialization mode, B set and read, the state restored;
- `two`: two instances of the FMU in one process, one with A set after entering initialization,
  one with B set before, called alternately; each agrees with its own reference.

Value sets A and B move every finite Real parameter and input start value, relative, by +DELTA or
+2 DELTA (A) and -2 DELTA or -DELTA (B), alternately, so that no ratio of two values is the same in
A and B; a start value 0 becomes DELTA or 2 DELTA (a weight or a gain 0 may not turn negative);
kept within the declared range. Outputs that are wall-clock
measurements (`CLOCKS`) are left out of the comparison. Each FMU runs in its own subprocess, which
leaves with os._exit (pythonfmu 0.7 may crash at interpreter exit in a Python host after FMPy's
freeInstance; that is the exit, not the call order, and another test's subject).

PlaneChangeOptimalGuidance solves for 8-13 s each time (twelve solves in the full set of orders):
it is checked in the slow set only; the four other FMUs on its base (EntryLatchedGuidance) run
every order by default.
"""

import json
import math
import os
import subprocess
import sys

import pytest

pytestmark = pytest.mark.integration

DELTA = 1e-3
STEPS = 3
CLOCKS = frozenset({"solve_time", "cycle_cpu"})
"""Outputs that are wall-clock or CPU times: never equal between two runs."""


ORDERS = ("after", "passes", "reset", "state", "two")
SLOW_SOLVES = ("PlaneChangeOptimalGuidance",)
"""FMUs checked in the slow set only (module docstring)."""


def value_sets(md):
    """(A, B): {Real parameter or input name: value}, the start values moved (module docstring)."""
    sets = ({}, {})
    reals = [v for v in md.modelVariables if v.causality in ("parameter", "input") and v.type == "Real"
             and v.start is not None and math.isfinite(float(v.start))]
    for k, var in enumerate(reals):
        start = float(var.start)
        low = -math.inf if var.min is None else float(var.min)
        high = math.inf if var.max is None else float(var.max)
        for values, factor in zip(sets, (1.0 + k % 2, -2.0 + k % 2)):
            moved = start + factor * DELTA * abs(start) if start else abs(factor) * DELTA
            values[var.name] = min(max(moved, low), high)
    return sets


class Driver:
    """One FMU file: FMPy instances and the traces of the call orders."""

    def __init__(self, path):
        from fmpy import extract, read_model_description

        self.md = read_model_description(path)
        self.folder = extract(path)
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.outputs = [v.name for v in self.md.modelVariables if v.causality == "output"]
        self.step = float(self.md.defaultExperiment.stepSize)
        self.count = 0

    def new(self):
        from fmpy.fmi2 import FMU2Slave

        self.count += 1
        fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=self.folder,
                        modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=f"i{self.count}")
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        return fmu

    def set(self, fmu, values):
        fmu.setReal([self.vr[n] for n in values], list(values.values()))

    def get(self, fmu):
        return dict(zip(self.outputs, fmu.getReal([self.vr[n] for n in self.outputs])))

    def finish(self, fmu, rows):
        """Exit initialization, step STEPS times; rows gets the outputs after each."""
        fmu.exitInitializationMode()
        rows.append(self.get(fmu))
        for k in range(STEPS):
            fmu.doStep(k * self.step, self.step)
            rows.append(self.get(fmu))
        return rows

    def reference(self, values):
        fmu = self.new()
        self.set(fmu, values)
        fmu.enterInitializationMode()
        return self.finish(fmu, [self.get(fmu)])

    def after(self, values):
        fmu = self.new()
        fmu.enterInitializationMode()
        self.set(fmu, values)
        return self.finish(fmu, [self.get(fmu)])

    def passes(self, a, b):
        """(rows, solve times read after the first set of A, after the second, after exit)."""
        fmu = self.new()
        fmu.enterInitializationMode()
        self.get(fmu)
        self.set(fmu, b)
        self.get(fmu)
        self.set(fmu, a)
        first = self.get(fmu)
        self.set(fmu, a)
        rows = self.finish(fmu, [self.get(fmu)])
        return rows, [row.get("solve_time") for row in (first, rows[0], rows[1])]

    def reset(self, a, b):
        fmu = self.new()
        self.set(fmu, b)
        fmu.enterInitializationMode()
        self.finish(fmu, [self.get(fmu)])
        fmu.reset()
        fmu.setupExperiment(startTime=0.0)
        self.set(fmu, a)
        fmu.enterInitializationMode()
        return self.finish(fmu, [self.get(fmu)])

    def state(self, a, b):
        fmu = self.new()
        fmu.enterInitializationMode()
        self.set(fmu, a)
        saved = fmu.getFMUstate()
        self.set(fmu, b)
        self.get(fmu)
        fmu.setFMUstate(saved)
        fmu.freeFMUstate(saved)
        return self.finish(fmu, [self.get(fmu)])

    def two(self, a, b):
        first, second = self.new(), self.new()
        self.set(second, b)
        first.enterInitializationMode()
        second.enterInitializationMode()
        self.set(first, a)
        rows = ([self.get(first)], [self.get(second)])
        for fmu, trace in zip((first, second), rows):
            fmu.exitInitializationMode()
            trace.append(self.get(fmu))
        for k in range(STEPS):
            for fmu, trace in zip((first, second), rows):
                fmu.doStep(k * self.step, self.step)
                trace.append(self.get(fmu))
        return rows


def differences(rows, expected):
    """['row k: name got ... expected ...'] where rows and expected differ (CLOCKS left out)."""
    out = []
    for k, (row, ref) in enumerate(zip(rows, expected)):
        for name, value in ref.items():
            got = row[name]
            if name not in CLOCKS and got != value and not (math.isnan(got) and math.isnan(value)):
                out.append(f"row {k}: {name} = {got!r}, reference {value!r}")
    return out


def conformance(path, orders):
    """{order: [differences from the reference]} of the FMU file `path` in `orders` (of ORDERS;
    with "passes", also "solved_once"), and "moved": whether A and B give different outputs."""
    driver = Driver(path)
    a, b = value_sets(driver.md)
    ref_a = driver.reference(a)
    report = {}
    if "passes" in orders:
        rows, solve_times = driver.passes(a, b)
        report["passes"] = differences(rows, ref_a)
        report["solved_once"] = [] if solve_times[0] is None or len(set(solve_times)) == 1 else \
            [f"solve_time after the first set of A, the second, exit: {solve_times}"]
    for order in set(orders) & {"after", "reset", "state"}:
        run = getattr(driver, order)
        report[order] = differences(run(a) if order == "after" else run(a, b), ref_a)
    if "two" in orders:
        first, second = driver.two(a, b)
        ref_b = driver.reference(b)
        report["two"] = differences(first, ref_a) + differences(second, ref_b)
        report["moved"] = differences(ref_b, ref_a) != []
    else:
        report["moved"] = differences(driver.after(b), ref_a) != []
    return report


@pytest.fixture(scope="module")
def built():
    from aotv_cosim.fmu import build as fmu_build

    return fmu_build.build_all()


def fmu_names():
    from aotv_cosim.fmu import build as fmu_build

    return fmu_build.available_fmus()


def check(fmu, orders, tmp_path):
    env = {**os.environ, "HOME": str(tmp_path)}
    done = subprocess.run([sys.executable, __file__, str(fmu), *orders], capture_output=True, text=True,
                          env=env, cwd=tmp_path, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    report = json.loads(done.stdout.strip().splitlines()[-1])
    assert report.pop("moved"), "value set B gives the same outputs as A: the test cannot tell orders apart"
    assert set(orders) <= set(report)
    assert report == {order: [] for order in report}


@pytest.mark.parametrize("name", [n for n in fmu_names() if n not in SLOW_SOLVES])
def test_every_legal_call_order_matches_the_reference(name, built, tmp_path):
    check(built[name], ORDERS, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("name", SLOW_SOLVES)
def test_every_legal_call_order_of_the_slow_solvers(name, built, tmp_path):
    check(built[name], ORDERS, tmp_path)


if __name__ == "__main__":
    print(json.dumps(conformance(sys.argv[1], sys.argv[2:])))
    sys.stdout.flush()
    os._exit(0)
