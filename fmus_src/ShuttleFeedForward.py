"""ShuttleFeedForward FMU: seed 003 feed-forward disturbance cancellation, eq. (2.16)."""

from aotv_cosim.fmu import guidance_slave
from aotv_cosim.fmu.slave import AotvSlave
from aotv_cosim.guidance.shuttle_laws import feed_forward


class ShuttleFeedForward(AotvSlave):
    """delta_e = f / mu from the PitchVehicle's coefficients: the reference transient response."""

    description = "Seed 003 feed-forward elevator law delta_e = f/mu (2.16)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        guidance_slave.declare_pitch_measurements(self, ('f', 'mu'))
        self.output("delta_e", "rad", "Commanded elevator deflection",
                    lambda: feed_forward(self.f, self.mu), depends_on=("f", "mu"))

    def do_step(self, current_time, step_size):
        return True
