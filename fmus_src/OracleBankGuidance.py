"""OracleBankGuidance FMU: the per-run oracle of bank-angle aerocapture (perfect knowledge)."""

import math
import time as clock
from dataclasses import replace

from pythonfmu.enums import Fmi2Status

from aotv_cosim.fmu.guidance_slave import EntryLatchedGuidance
from aotv_cosim.fmu.slave import POSITIVE
from aotv_cosim.guidance import lateral, oracle_bank
from aotv_cosim.physics import aerocapture_vehicles as av
from aotv_cosim.physics.constants import MU_EARTH, R_EARTH_000


def _finite(x: float) -> float:
    """x, or 1.8e308 when it is not a number (an FMU output must be finite)."""
    return x if math.isfinite(x) else 1.8e308


class OracleBankGuidance(EntryLatchedGuidance):
    """The minimum-dv pass of this run, solved at initialization with the run's truth and flown
    open loop (`aotv_cosim.guidance.oracle_bank`): full lift up to a switch point, then a constant
    bank that puts the exit apogee on the target. Its model parameters must be the run's own: a
    scenario binds them to the vehicle's, the Atmosphere's and the actuator's (`"bindings"`,
    `model.bindings`), dispersed values included; the Atmosphere's time noise (noise_amplitude)
    is not modelled. The solve predicts the co-simulated pass as the master flies the
    aerocapture sets (Gauss-Seidel in the order vehicle, atmosphere, this FMU, actuator; step
    command_period; input_extrapolation as the scenario's inputs): a step of another size is
    flown with a warning in the log (the pass is then not the predicted one). The sign of the bank
    follows `guidance.lateral` with `deadband` (pi: no reversal).
    `saturation_time` integrates the time the command sits on a bound of |sigma| (0 or pi), for
    the sets' records. A plan that is not admissible (no pass meets the target) is flown all the
    same, flagged by `admissible` 0."""

    description = "Per-run oracle: minimum-dv two-arc bank profile solved with the run's truth"
    default_step = 1.0  # command_period's default: the DefaultExperiment steps as the plan commands
    entry_start = (av.H_INTERFACE, av.geo_return_speed(), math.radians(-4.87))

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        d = oracle_bank.OracleSettings(av.TARGET_APOGEE, av.H_INTERFACE)
        p = self.parameter
        p("apogee_target", d.apogee_target, "m", "Target apogee altitude of the exit orbit",
          nominal=d.apogee_target)
        p("h_exit", d.h_exit, "m", "Atmospheric interface altitude of the exit", nominal=d.h_exit)
        p("tolerance", d.tolerance, "m", "Accepted |predicted apogee - target| of a solve", min=POSITIVE)
        p("command_period", d.command_period, "s", "Period of the bank command: the scenario's step",
          min=POSITIVE)
        p("horizon", d.horizon, "s", "End of the run after the start: the longest prediction", min=POSITIVE)
        p("horizon_margin", d.horizon_margin, "s", "A pass must exit this long before the horizon", min=0.0)
        p("deadband", d.deadband, "rad", "Plane-error deadband of the bank reversals", min=0.0)
        self.integer_parameter("input_extrapolation", d.input_extrapolation, "1: the scenario extrapolates the "
                               "delayed inputs (step inputs 'extrapolated', the sets'); 0: holds them", min=0, max=1)
        p("max_substep", d.max_substep, "s", "The vehicle's longest RK4 substep (bind to the vehicle's)",
          min=POSITIVE)
        p("h_floor", d.h_floor, "m", "A prediction below this altitude does not exit")
        p("sigma_2_max", d.sigma_2_max, "rad", "Largest bank of the exit arc", min=0.0, max=math.pi)
        p("CL", av.AOTV.cl, "1", "Lift coefficient at trim (bind to the vehicle's)")
        p("CD", av.AOTV.cd, "1", "Drag coefficient at trim (bind to the vehicle's)", min=POSITIVE)
        p("S_ref", av.AOTV.s_ref, "m2", "Reference area (bind to the vehicle's)", min=POSITIVE)
        p("mass", av.AOTV.mass, "kg", "Vehicle mass (bind to the vehicle's)", min=POSITIVE)
        self.integer_parameter("atmosphere_model", 1, "Density model: 0 exponential, 1 US76 (bind to the "
                               "Atmosphere's model)", min=0, max=1)
        p("rho_ref", 1.225, "kg/m3", "Exponential density at h_ref (bind to the Atmosphere's)")
        p("h_ref", 0.0, "m", "Reference altitude of the exponential density (bind to the Atmosphere's)")
        p("scale_height", 7000.0, "m", "Scale height of the exponential density (bind to the Atmosphere's)",
          min=POSITIVE)
        p("density_factor", 1.0, "1", "Constant density multiplier (bind to the Atmosphere's)")
        p("profile_sigma", 0.0, "1", "Standard deviation of the random ln-density profile (bind)", min=0.0)
        p("profile_length", 10000.0, "m", "Correlation length of the random profile (bind)", min=1.0)
        p("profile_seed", 0.0, "1", "Seed of the random profile, integer part (bind)", min=0.0)
        p("rate_limit", math.radians(20.0), "rad/s", "Bank actuator's rate limit (bind)", min=POSITIVE)
        p("accel_limit", math.radians(5.0), "rad/s2", "Bank actuator's acceleration limit (bind)", min=POSITIVE)
        p("R_e", R_EARTH_000, "m", "Planet radius (bind to the vehicle's)", min=POSITIVE)
        p("mu", MU_EARTH, "m3/s2", "Gravitational parameter (bind to the vehicle's)", min=POSITIVE)
        self.input("phi", 0.0, "rad", "Latitude (plane error; latched at initialization for the solve)")
        self.input("psi", 0.0, "rad", "Heading (plane error; latched at initialization for the solve)")
        out = self.solution_output
        out("sigma", "rad", "Bank angle command: the plan's magnitude, the lateral logic's sign",
            self.current_command)
        out("t_switch", "s", "Switch point after the start", lambda: self.solution().t_switch)
        out("sigma_2", "rad", "Bank of the exit arc", lambda: self.solution().sigma_2)
        out("apogee_pred", "m", "Predicted exit apogee altitude (1.8e308 if unbound, -1.8e308 if no exit)",
            lambda: max(-1.8e308, min(self.solution().prediction.apogee, 1.8e308)))
        out("dv_pred", "m/s", "Predicted correction dv to the circular target orbit (1.8e308 without a bound exit)",
            lambda: _finite(self.solution().prediction.dv_total))
        out("exit_time_pred", "s", "Predicted exit time after the start", lambda: self.solution().prediction.t)
        out("admissible", "1", "1 if the predicted pass meets the target apogee, else 0",
            lambda: 1.0 if self.solution().admissible else 0.0)
        out("predictions", "1", "Predictions flown by the solve", lambda: float(self.solution().predictions))
        out("solve_time", "s", "CPU time of the solve (process time)", lambda: self.solution().solve_cpu)
        self.output("saturation_time", "s", "Time the command sat on a bound of |sigma| (0 or pi)",
                    lambda: self.saturation_time)
        self.saturation_time, self.sign, self.warned = 0.0, 1, False

    entry_inputs = ("h", "v", "gamma", "phi", "psi")

    def start_state(self):
        super().start_state()
        self.saturation_time, self.sign, self.warned = 0.0, 1, False

    def _model(self):
        s_m = self.S_ref / self.mass
        return oracle_bank.TruthModel(
            self.CL * s_m, self.CD * s_m, density_factor=self.density_factor, profile_sigma=self.profile_sigma,
            profile_length=self.profile_length, profile_seed=self.profile_seed,
            atmosphere_model=int(self.atmosphere_model), rho_ref=self.rho_ref, h_ref=self.h_ref,
            scale_height=self.scale_height, rate_limit=self.rate_limit, accel_limit=self.accel_limit,
            r_earth=self.R_e, mu=self.mu)

    def _settings(self):
        return oracle_bank.OracleSettings(
            self.apogee_target, self.h_exit, command_period=self.command_period, tolerance=self.tolerance,
            h_floor=self.h_floor, horizon=self.horizon, horizon_margin=self.horizon_margin,
            deadband=self.deadband, input_extrapolation=int(self.input_extrapolation),
            max_substep=self.max_substep, sigma_2_max=min(self.sigma_2_max, oracle_bank.LIFT_DOWN))

    def solve(self):
        start = clock.process_time()
        plan = oracle_bank.solve((self.h, self.v, self.gamma, self.phi, self.psi), self._model(), self._settings())
        return replace(plan, solve_cpu=clock.process_time() - start)

    def final_time(self, solution):
        return math.inf

    def command(self, solution, elapsed):
        return self.sign * solution.command(elapsed)

    def do_step(self, current_time, step_size):
        if abs(step_size - self.command_period) > 1e-9 * self.command_period and not self.warned:
            self.warned = True
            self.log(f"OracleBankGuidance: step of {step_size:g} s: the plan predicts a command every "
                     f"command_period = {self.command_period:g} s, so this pass is not the predicted one; "
                     "give the scenario that step", Fmi2Status.warning)
        magnitude = abs(self.current_command())
        if magnitude == 0.0 or magnitude >= oracle_bank.LIFT_DOWN:
            self.saturation_time += step_size
        self.sign = lateral.bank_sign(self.sign, lateral.plane_error(self.phi, self.psi), self.deadband)
        return self.advance(current_time, step_size)
