"""AngleActuator FMU: one angular channel (rad) with saturation, rate limit and lag."""

from aotv_cosim.fmu import actuator_slave


class AngleActuator(actuator_slave.ActuatorSlave):
    """Actuator for an angle command in rad: bank (seeds 001, 002), angle of attack (seed 002),
    elevator (seed 003, +-25 deg). Limits in rad, rate limit in rad/s."""

    description = "Angle actuator (rad): saturation, rate limit, first-order lag (all off by default)"
    unit = "rad"

    def do_step(self, current_time, step_size):  # defined here: see fmu.build.check_defines_do_step
        return self.advance(step_size)
