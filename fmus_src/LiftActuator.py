"""LiftActuator FMU: one lift-acceleration channel (m/s^2) with saturation, rate limit and lag."""

from aotv_cosim.fmu import actuator_slave


class LiftActuator(actuator_slave.ActuatorSlave):
    """Actuator for a lift-acceleration command, u = L/m in m/s^2 (seed 000 eq. 2.9)."""

    description = "Lift-acceleration actuator: saturation, rate limit, first-order lag (all off by default)"
    unit = "m/s2"

    def do_step(self, current_time, step_size):  # defined here: see fmu.build.check_defines_do_step
        return self.advance(step_size)
