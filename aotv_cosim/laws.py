"""The extension point: the bases of an FMU of your own (a guidance law, an actuator, a vehicle).

Write one Python file holding one class derived from a base below, then build it
(`aotv-cosim build-fmus MyLaw.py`) or name the file in a wiring (``"fmu": "laws/MyLaw.py"``,
relative to the wiring, built on first use). The tutorial is docs/writing-a-guidance-law.md.
These names are stable: they are what a user's FMU source imports.

- `AotvSlave`: any FMU. Declare variables in ``__init__`` with `parameter`, `integer_parameter`,
  `input` and `output` (name, start, SI unit, description, optional min/max; an output names the
  inputs it depends on at the same instant), and define ``do_step(self, current_time,
  step_size)`` returning True (False: the step is refused, fmi2Discard).
- `EntryLatchedGuidance`: a law solved once from the measured entry state h, v, gamma at
  initialization and flown open loop; define `solve`, `final_time`, `command`, and
  ``do_step`` as ``return self.advance(current_time, step_size)``.
- `NominalTrackingGuidance`: feedback about the seed-000 optimal nominal; define `design` (a
  `aotv_cosim.guidance.tracking` law), call `law_outputs()` last in ``__init__``, and ``do_step``
  as ``return self.advance(current_time, step_size)``.
- `ActuatorSlave`, `VehicleSlave`: the actuator and point-mass vehicle bases of the shipped FMUs.

Rules checked when the class is defined or instantiated:

- A concrete class defines ``do_step`` in its own body (pythonfmu 0.7 finds the FMU class through
  it); a class that inherits it raises TypeError at its definition.
- Units are SI unit strings, parsed by `unit_exponents` ("m/s2", "kg/(s.m)", "N.m", "1" for
  dimensionless); anything else raises ValueError when the FMU is instantiated.
- An exception raised in ``do_step`` is logged with its traceback (file and line) through the FMI
  logger before the run stops: it is in summary.json (``error_detail.fmu_log``) and printed with
  ``aotv-cosim --debug run``.
- The FMU state saved by fmi2GetFMUstate (used by the adaptive step control and by tools that
  roll back) follows `SAVED_STATE`; attributes named in `NOT_STATE` are never saved.

The FMU bundles this package's runtime (physics, guidance, these bases), so the law may import
``aotv_cosim.physics`` and ``aotv_cosim.guidance``, numpy and scipy, and nothing else that is not
installed where the FMU runs.
"""

from aotv_cosim.fmu.actuator_slave import ActuatorSlave
from aotv_cosim.fmu.guidance_slave import (EntryLatchedGuidance, NominalTrackingGuidance,
                                           declare_exit_targets, declare_exit_targets_and_k)
from aotv_cosim.fmu.slave import NOT_STATE, POSITIVE, SAVED_STATE, AotvSlave, unit_exponents
from aotv_cosim.fmu.vehicle_slave import VehicleSlave

__all__ = ["AotvSlave", "EntryLatchedGuidance", "NominalTrackingGuidance", "ActuatorSlave", "VehicleSlave",
           "declare_exit_targets", "declare_exit_targets_and_k", "unit_exponents", "POSITIVE",
           "NOT_STATE", "SAVED_STATE"]
