"""In-flight density estimation for the bank-angle NPC: sensed over modelled density, kept by altitude.

Sensed density ratio. From the drag specific force the accelerometers sense, D/m, and the
navigated altitude h and speed v, the ratio to the predictor model's drag at scale 1,

    K = (D/m)_sensed / (rho_model(h) v^2 (C_D S/m)_model / 2),

is rho_true(h)/rho_model(h) times (C_D S/m)_true/(C_D S/m)_model: exactly the scale the predictor's
drag needs. The sensed lift-to-drag ratio (L/m)/(D/m) gives the predictor's lift,
(C_L S/m) := (L/D)_sensed (C_D S/m)_model, so that its lift is right wherever its drag is.

Three estimates of K ahead of the vehicle:

- **Fading memory** (the first-order filter of FNPAG's density estimation that Calkins, McMahon,
  Doostan & Woffinden, "Risk-aware aerocapture guidance through a probabilistic indicator
  function", arXiv 2507.05454, 2025, compare against): k <- k + gain (K - k) at every sample, one
  number for the whole rest of the pass.
- **Altitude table** (a density array, as the "density interpolator" of Roelke, Hattis & Braun,
  "Improved atmospheric estimation for aerocapture guidance", AAS 19-725, 2019): the K measured
  on the way down, by altitude. A density perturbation that depends on altitude only (GRAM-style
  profiles, `physics.density_profile`) is met again on the way up through the same altitudes,
  so above the lowest altitude measured so far, h_min, the predictor flies the measured K(h)
  (piecewise linear between samples).
- **Below h_min** (not measured yet): the conditional mean of a first-order Gauss-Markov process
  in altitude with correlation length L, in ln K:
      ln K(h) = mu + (ln K(h_min) - mu) exp(-(h_min - h) / L),
  which starts at the last measured value and relaxes, over a few L, to mu, the mean ln K over
  the altitudes measured so far (trapezoidal in altitude). L is the designer's correlation
  length of the atmosphere's perturbations (a GRAM-style statistic, 10 km in the benchmark's
  dispersion set), not a property of the run.

Samples whose sensed drag is below `drag_floor` (m/s^2) are not used (the upper atmosphere, where
an accelerometer measures little but its noise); until the first usable sample the prior scale is
flown. Units: SI (m, m/s, m/s^2); K and k dimensionless.
"""

import math
from dataclasses import dataclass, replace

from aotv_cosim.guidance.npc_bank import BankModel, ScaleProfile

RELAXATION_NODES = (0.25, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0)
"""Depths below h_min, in correlation lengths, of the nodes that carry the relaxation to mu in
the predictor's piecewise-linear scale (below the last one mu is held: exp(-4) = 1.8 %)."""


def sensed_ratio(h: float, v: float, drag_acc: float, model: BankModel) -> float:
    """K: sensed drag (m/s^2) over the model's drag at scale 1 at altitude h (m) and speed v (m/s);
    nan when either is not positive."""
    modelled = model.drag(h, v, 1.0)
    if not (drag_acc > 0.0 and modelled > 0.0):
        return math.nan
    return drag_acc / modelled


@dataclass(frozen=True)
class DensityEstimate:
    """What the estimator keeps: the descent's samples (altitudes m, strictly descending, and
    their K), the integral of ln K over their altitudes (trapezoidal, m), the fading-memory K and
    the fading-memory sensed L/D (None before the first usable sample), and the last sample taken
    (h, v, drag, lift; the same sample offered again, as when a cycle reads the inputs a step has
    already sampled, is not counted twice)."""

    altitudes: tuple = ()
    ratios: tuple = ()
    log_area: float = 0.0
    filtered: float | None = None
    lift_to_drag: float | None = None
    last: tuple | None = None

    def add(self, h: float, v: float, drag_acc: float, lift_acc: float, model: BankModel, gain: float,
            drag_floor: float) -> "DensityEstimate":
        """The estimate after a sample of the navigated (h m, v m/s) and sensed lift and drag
        (m/s^2): the fading-memory K and L/D updated with `gain` (the first sample sets them);
        appended to the table if h is below every altitude sampled before. A sample with sensed
        drag below drag_floor (m/s^2), or K not a positive number, or the last sample again,
        leaves it unchanged."""
        if self.last == (h, v, drag_acc, lift_acc):
            return self
        ratio = sensed_ratio(h, v, drag_acc, model)
        if not (drag_acc >= drag_floor and ratio > 0.0 and math.isfinite(ratio)):
            return self
        lift_to_drag = lift_acc / drag_acc
        if self.filtered is None:
            filtered = ratio
        else:
            assert self.lift_to_drag is not None  # set with `filtered`, at the first usable sample
            filtered = self.filtered + gain * (ratio - self.filtered)
            lift_to_drag = self.lift_to_drag + gain * (lift_to_drag - self.lift_to_drag)
        altitudes, ratios, log_area = self.altitudes, self.ratios, self.log_area
        if not altitudes or h < altitudes[-1]:
            if altitudes:
                log_area += 0.5 * (math.log(ratios[-1]) + math.log(ratio)) * (altitudes[-1] - h)
            altitudes, ratios = (*altitudes, h), (*ratios, ratio)
        return DensityEstimate(altitudes, ratios, log_area, filtered, lift_to_drag, (h, v, drag_acc, lift_acc))

    def mean_log_ratio(self) -> float:
        """mu: the mean of ln K over the altitudes sampled (trapezoidal in altitude; the one
        sample's ln K if there is one)."""
        if len(self.altitudes) == 1:
            return math.log(self.ratios[0])
        return self.log_area / (self.altitudes[0] - self.altitudes[-1])

    def table_profile(self, correlation_length: float, prior: float = 1.0) -> ScaleProfile:
        """The predictor's scale: the measured K(h) above h_min, the Gauss-Markov relaxation to mu
        below (module docstring) with correlation_length L (m); `prior` before any sample."""
        if not self.altitudes:
            return ScaleProfile((0.0,), (prior,))
        h_min, log_min, mu = self.altitudes[-1], math.log(self.ratios[-1]), self.mean_log_ratio()
        depths = RELAXATION_NODES[::-1]
        below_h = tuple(h_min - depth * correlation_length for depth in depths)
        below_k = tuple(math.exp(mu + (log_min - mu) * math.exp(-depth)) for depth in depths)
        return ScaleProfile(below_h + self.altitudes[::-1], below_k + self.ratios[::-1])

    def filtered_profile(self, prior: float = 1.0) -> ScaleProfile:
        """The fading-memory K as a constant scale (`prior` before any sample)."""
        return ScaleProfile((0.0,), (prior if self.filtered is None else self.filtered,))


ESTIMATOR_NAVIGATED, ESTIMATOR_FADING, ESTIMATOR_TABLE = 0, 1, 2
"""Density estimators of the bank NPC: the fading-memory scale of the drag read off the navigated
state between cycles (`npc.measured_density_ratio`, FNPAG as first shipped), the fading-memory
sensed K, the altitude table of sensed K (module docstring)."""


def predictor_inputs(estimate: DensityEstimate, estimator: int, model: BankModel, correlation_length: float,
                     prior: float, lift_to_drag: bool):
    """(scale, model) the predictor flies with the sensed estimate: the `estimator`'s scale
    (ESTIMATOR_FADING or ESTIMATOR_TABLE) and, if lift_to_drag, the model's C_L S/m set from the
    sensed L/D."""
    if estimator == ESTIMATOR_TABLE:
        scale = estimate.table_profile(correlation_length, prior)
    else:
        scale = estimate.filtered_profile(prior)
    if lift_to_drag and estimate.lift_to_drag is not None:
        model = replace(model, cl_s_m=estimate.lift_to_drag * model.cd_s_m)
    return scale, model
