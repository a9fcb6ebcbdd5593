"""NpcBankDensityGuidance FMU: the bank-angle NPC with in-flight density estimation from sensed drag."""

import math

from aotv_cosim.fmu.bank_guidance import BankNpcGuidance
from aotv_cosim.fmu.slave import POSITIVE
from aotv_cosim.guidance import density_estimation as de
from aotv_cosim.guidance import npc_bank

MEASURED = ("h", "v", "gamma", "drag_acc", "lift_acc")


class NpcBankDensityGuidance(BankNpcGuidance):
    """The bank-angle NPC (`aotv_cosim.fmu.bank_guidance`: every cycle_period s, predict to exit
    with the vehicle's own model and correct the constant bank magnitude by secant,
    `guidance.npc_bank`; bank sign from the lateral logic) whose predictor flies the density
    estimated from the sensed drag (`guidance.density_estimation`): at every communication step the
    ratio K of the sensed drag drag_acc to the model's drag at the navigated h, v is sampled; by
    default (density_estimator 2) the predictor flies the K measured on the way down wherever it
    climbs back through those altitudes, and below the lowest altitude sampled the Gauss-Markov
    relaxation from the last K to the mean ln K over correlation_length; its lift comes from the
    sensed L/D (lift_acc / drag_acc). density_estimator 1 flies the fading-memory K instead (the
    comparison filter). A cycle's result depends on the inputs at the cycle time, the samples of the
    previous steps and the memory they committed. The model parameters must match the vehicle and
    Atmosphere FMUs of the system."""

    description = ("Bank-angle numerical predictor-corrector aerocapture guidance with density estimated from "
                   "sensed drag")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.declare_corrector()
        p = self.parameter
        p("sigma_guess", math.pi / 2, "rad", "First-cycle guess of the bank magnitude", min=0.0, max=math.pi)
        p("density_gain", 0.3, "1", "Gain of the fading-memory filters (0: keep the first sample)", min=0.0,
          max=1.0)
        self.integer_parameter("density_estimator", de.ESTIMATOR_TABLE,
                               "Density estimate: 1 fading-memory scale of the sensed drag every step; 2 altitude table "
                               "of the sensed drag, Gauss-Markov relaxation below the lowest altitude sampled",
                               min=1, max=2)
        self.integer_parameter("estimate_lift_to_drag", 1, "1: the predictor's lift from the sensed L/D; 0: from CL",
                               min=0, max=1)
        p("correlation_length", 10000.0, "m", "Altitude correlation length of the density perturbations "
          "(estimator 2)", min=POSITIVE)
        p("drag_floor", 0.05, "m/s2", "Sensed drag below which a sample is not used", min=0.0)
        self.declare_plant()
        self.input("drag_acc", 0.0, "m/s2", "Sensed drag specific force")
        self.input("lift_acc", 0.0, "m/s2", "Sensed lift specific force")
        self.declare_outputs(MEASURED, "Estimated density scale K at the altitude of the last cycle")

    def _reset(self):
        super()._reset()
        self.estimate = de.DensityEstimate()

    def run_cycle(self, memory, t, state):
        scale, model = de.predictor_inputs(self._sampled(), self.density_estimator, self._model(),
                                           self.correlation_length, 1.0, bool(self.estimate_lift_to_drag))
        return npc_bank.cycle_with_scale(memory, t, state, scale, model, self._settings())

    def _sampled(self):
        """The density estimate with the present inputs sampled."""
        return self.estimate.add(self.h, self.v, self.drag_acc, self.lift_acc, self._model(), self.density_gain,
                                 self.drag_floor)

    def sample(self):
        self.estimate = self._sampled()

    def current_command(self):
        x = self._cycle()[0].u_c
        return self.sign * math.acos(max(-1.0, min(1.0, x)))

    def do_step(self, current_time, step_size):
        return self.advance(current_time, step_size)
