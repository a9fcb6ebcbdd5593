"""LiftCoefficientActuator FMU: a dimensionless lift channel (normalized lift lambda, seed 001)."""

from aotv_cosim.fmu import actuator_slave


class LiftCoefficientActuator(actuator_slave.ActuatorSlave):
    """Actuator for a dimensionless command such as lambda = C_L/C_L*, limited to [0, lambda_max]
    in seed 001 (set lower/upper)."""

    description = "Dimensionless actuator (e.g. normalized lift): saturation, rate limit, lag"
    unit = "1"

    def do_step(self, current_time, step_size):  # defined here: see fmu.build.check_defines_do_step
        return self.advance(step_size)
