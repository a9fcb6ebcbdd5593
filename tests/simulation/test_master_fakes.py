"""The master's logic on fake FMUs: pythonfmu slave classes defined here and called in-process
(`direct_instance.info_of_class`), so no FMU is built and each run takes milliseconds.

Two fakes: `Ramp` (output y = the time it reached) and `Hold` (output z = the input u it was given
before its step; no feedthrough). Wired ramp.y -> hold.u, the value hold.z holds after a step
says which value of ramp.y the master passed: the one at the new communication point (Gauss-Seidel,
the ramp steps first) or the one at the old point (Jacobi)."""

import json
import struct
from types import SimpleNamespace

import pytest
from pythonfmu import Fmi2Causality, Fmi2Slave, Real

from aotv_cosim.simulation.direct_instance import info_of_class
from aotv_cosim.simulation.master import Master
from aotv_cosim.simulation.loading import load_scenario
from aotv_cosim.status import Status


class Ramp(Fmi2Slave):
    """y = t at the end of each step; asks to end the run (do_step false) past `end_at` s."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.y, self.end_at = 0.0, 1e9
        self.register_variable(Real("end_at", causality=Fmi2Causality.parameter))
        self.register_variable(Real("y", causality=Fmi2Causality.output))

    def do_step(self, current_time, step_size):
        if current_time + step_size > self.end_at:
            return False
        self.y = current_time + step_size
        return True


class Hold(Fmi2Slave):
    """z = the input u as it was when the step began."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.u, self.z = 0.0, 0.0
        self.register_variable(Real("u", causality=Fmi2Causality.input))
        self.register_variable(Real("z", causality=Fmi2Causality.output))

    def do_step(self, current_time, step_size):
        self.z = self.u
        return True


FAKES = {"Ramp": Ramp, "Hold": Hold}


def fakes(name):
    """The FMU resolver of these tests: each name is a slave class above, called in-process."""
    return info_of_class(FAKES[name], name)


def scenario(tmp_path, **changes):
    wiring = {"components": {"ramp": {"fmu": "Ramp"}, "hold": {"fmu": "Hold"}},
              "connections": ["ramp.y -> hold.u"]}
    (tmp_path / "wiring.json").write_text(json.dumps(wiring))
    doc = {"system": "wiring.json", "start": 0.0, "stop": 1.0, "step": 0.25,
           "record": ["ramp.y", "hold.z"], **changes}
    (tmp_path / "scenario.json").write_text(json.dumps(doc))
    return load_scenario(tmp_path / "scenario.json", fmus=fakes)


def run(scenario):
    """(outcome, {column: [values]}, times) of one run on the direct path."""
    times, rows = [], []
    master = Master(scenario, fmi_calls="direct")
    outcome = master.run(SimpleNamespace(record=lambda t, r: (times.extend(t), rows.extend(r))))
    columns = {sig: [struct.unpack_from("d", row, 8 * master.index[sig])[0] for row in rows]
               for sig in master.index}  # a recorded row is the bytes of the master's float64 buffer
    return outcome, columns, times


def test_gauss_seidel_passes_the_value_at_the_new_communication_point(tmp_path):
    outcome, col, times = run(scenario(tmp_path))
    assert outcome.status == Status.COMPLETED and times == [0.0, 0.25, 0.5, 0.75, 1.0]
    assert col["hold.z"] == col["ramp.y"] == times


def test_jacobi_passes_the_value_at_the_old_communication_point(tmp_path):
    outcome, col, times = run(scenario(tmp_path, algorithm="jacobi"))
    assert outcome.status == Status.COMPLETED
    assert col["ramp.y"] == times and col["hold.z"] == [0.0, *times[:-1]]


def test_a_stop_condition_ends_the_run_at_its_interpolated_crossing(tmp_path):
    outcome, _col, times = run(scenario(tmp_path, stop_conditions=[
        {"signal": "ramp.y", "crosses": 0.6, "direction": "up"}]))
    assert outcome.status == Status.COMPLETED and times[-1] == 0.75
    assert outcome.event["time"] == pytest.approx(0.6) and "ramp.y crossed 0.6 up" in outcome.stop_reason


def test_a_terminate_request_ends_the_run_with_the_rows_before_it(tmp_path):
    outcome, _col, times = run(scenario(tmp_path, parameters={"ramp.end_at": 0.6}))
    assert outcome.status == Status.TERMINATED and times == [0.0, 0.25, 0.5]
    assert outcome.terminate_request["component"] == "ramp"
