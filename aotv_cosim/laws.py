"""The extension point: the bases of an FMU of your own (a guidance law, an actuator, a vehicle).

Write one Python file holding one class derived from a base below, then build it
(`aotv-cosim build-fmus MyLaw.py`) or name the file in a wiring (``"fmu": "laws/MyLaw.py"``,
relative to the wiring, built on first use). The tutorial is docs/writing-a-guidance-law.md.
These names are stable: they are what a user's FMU source imports.

- `AotvSlave`: any FMU. Declare variables in ``__init__`` with `parameter`, `integer_parameter`,
  `input` and `output` (name, start, SI unit, description; optional ``min``/``max``, SI and
  inclusive, on all four, and ``nominal``, the quantity's typical magnitude, on `parameter` and
  `input`; an output names the inputs it depends on at the same instant), and define
  ``do_step(self, current_time, step_size)`` returning True (`STEP_CONTRACT`).
- `EntryLatchedGuidance`: a law solved once from the measured entry state h, v, gamma at
  initialization and flown open loop; define `solve`, `final_time`, `command`, and
  ``do_step`` as ``return self.advance(current_time, step_size)``.
- `NominalTrackingGuidance`: feedback about the seed-000 optimal nominal; define `design` (a
  `aotv_cosim.guidance.tracking` law), call `law_outputs()` last in ``__init__``, and ``do_step``
  as ``return self.advance(current_time, step_size)``.
- `ActuatorSlave`, `VehicleSlave`: the actuator and point-mass vehicle bases of the shipped FMUs.

A plain pythonfmu ``Fmi2Slave`` class builds too (`build-fmus` completes the ModelStructure
pythonfmu leaves out, and holds its do_step to the same contract); it declares no units, ranges
or nominal values, and its FMU does not save its state.

Rules checked when the file is built (`aotv_cosim.fmu.source_check`) or the class defined:

- The file is imported once, in a child process, never in the building command's own: code at
  import runs once per build, no ``__pycache__`` is written beside the file. Importing it,
  instantiating the class and writing its modelDescription must end within
  ``aotv_cosim.fmu.source_check.IMPORT_TIME_LIMIT`` (60 s); a hang, ``sys.exit``,
  ``os._exit``, a crash or an exception is refused (exit 2) naming the file and the line.
- One FMU class per file: two concrete Fmi2Slave classes are refused, naming both. A shared
  abstract base may stay in the file if the class derives from it; a base class imported by name
  that lies deeper below Fmi2Slave than the class is refused (the FMU's runtime would take it).
- The file is decoded per PEP 263: UTF-8, or the encoding its first or second line declares
  (``# -*- coding: latin-1 -*-``); a byte that does not decode is a syntax error with its line.
- A concrete class defines ``do_step`` in its own body (pythonfmu 0.7 finds the FMU class through
  it); a class that inherits it raises TypeError at its definition.
- Units are SI unit strings, parsed by `unit_exponents` ("m/s2", "kg/(s.m)", "N.m", "1" for
  dimensionless); anything else ("km", "deg") is refused when the file is built, naming the
  variable (exit 2). A ``min`` above ``max``, a start outside them or a ``nominal`` that is not a
  finite number above 0 likewise.
- A value given to a parameter or an unconnected input (wiring, scenario, ``--set``, Monte Carlo
  draws) outside its ``min``/``max`` is refused (exit 2); one more than 30 times above or below
  its ``nominal`` is warned about with the likely unit slip (``output.plausibility``).
- ``do_step`` follows `STEP_CONTRACT`: True, the step is done; False, it is refused and the run
  fails saying so; None (a forgotten ``return``) is an error naming the file and line of the
  do_step. An exception raised in ``do_step`` is logged with its traceback (file and line)
  through the FMI logger before the run stops: it is in summary.json
  (``error_detail.fmu_log``) and printed with ``aotv-cosim --debug run``.
- The FMU state saved by fmi2GetFMUstate (used by the adaptive step control and by tools that
  roll back) follows `SAVED_STATE`; attributes named in `NOT_STATE` are never saved.

The FMU bundles this package's runtime (physics, guidance, these bases), so the law may import
``aotv_cosim.physics`` and ``aotv_cosim.guidance``, numpy and scipy, and nothing else that is not
installed where the FMU runs.
"""

from aotv_cosim.fmu.actuator_slave import ActuatorSlave
from aotv_cosim.fmu.guidance_slave import (EntryLatchedGuidance, NominalTrackingGuidance,
                                           declare_exit_targets, declare_exit_targets_and_k)
from aotv_cosim.fmu.slave import NOT_STATE, POSITIVE, SAVED_STATE, STEP_CONTRACT, AotvSlave, unit_exponents
from aotv_cosim.fmu.vehicle_slave import VehicleSlave

__all__ = ["NOT_STATE", "POSITIVE", "SAVED_STATE", "STEP_CONTRACT", "ActuatorSlave", "AotvSlave",
           "EntryLatchedGuidance", "NominalTrackingGuidance", "VehicleSlave", "declare_exit_targets",
           "declare_exit_targets_and_k", "unit_exponents"]
