"""Numerical predictor-corrector (NPC) guidance of the seed-000 aeroassisted transfer.

In the spirit of FNPAG (Lu, Cerimele, Tigges & Matz, "Optimal aerocapture guidance", JGCD 38(4),
2015, the fully numerical predictor-corrector aerocapture guidance) and of the unified entry
guidance of Lu ("Entry guidance: a unified method", JGCD 37(3), 2014): at each guidance cycle the
vehicle model is integrated numerically from the measured state to atmospheric exit, and one
parameter of the lift profile is corrected by a secant iteration until the predicted apogee of the
exit orbit meets the target.

Model (the predictor). The same equations of motion as the vehicle FMUs,
`physics.point_mass.derivatives` (seed 000 eq. 2.7 in the planar case: bank 0, constant g),
integrated by classical RK4 with step `step` s; the density is the exponential atmosphere
(seed 000 eq. 2.5, `physics.atmosphere.exponential_density`) times the estimated scale k_rho, and
is evaluated at every RK4 stage; the drag is parasite drag D/m = rho v^2 C_D0 / (2 m/S) (eq. 2.6).

Lift profile (one parameter u_c, the command now, at the cycle time t_k), phase 1 / phase 2:
    t_k <  t_s:  u(t) = u_c + (u_f - u_c) (t - t_k) / (t_s - t_k)  for t_k <= t < t_s,  u_f after;
    t_k >= t_s:  u(t) = u_c                                      (constant command after the switch).
With u_f = 0 and t_s = t_f = 300 s, phase 1 is the family of the approximate time-linear law
(4.23), u = -lambda_r(t_f)(t_f - t)/(2R), a straight line through (t_f, 0), and u_c plays the part
of the costate lambda_r(t_f), re-solved every cycle from the measured state.

Predicted quantities at the exit crossing h = h_exit (climbing; linear interpolation inside the
RK4 step): apogee of the Keplerian orbit (`physics.orbit`, seed-000 extraction
Sec. 7). Miss function of the corrector: z(u_c) = h_a(u_c) - h_a*, with h_a* the target apogee
altitude (default: the apogee of the Table 4.1 exit state, 1191.15 km, the LEO of the transfer).

Corrector (Lu 2014 and Lu et al. 2015: secant on the one-parameter miss):
    u_c^(i+1) = u_c^(i) - z^(i) (u_c^(i) - u_c^(i-1)) / (z^(i) - z^(i-1)),
safeguarded (`correct`): steps at most du_max long until two iterates bracket the root, then
false position with the Illinois modification inside the bracket (secant or bisection when an
end is an unbound or non-exiting prediction, whose miss is not a usable number); u_c stays in
[u_min, u_max]. The first cycle starts from a guess;
later cycles start from the previous cycle's solution (warm start).

Density scale estimate (FNPAG compares the sensed drag against the model's, low-pass
filtered). Here the drag is read off the navigated state, with no accelerometer input: between
two cycles, v_dot = -D/m - g sin(gamma) (eq. 2.7) gives the mean drag
    D_meas = -(v_1 - v_0)/dt - g (sin gamma_0 + sin gamma_1)/2,
the model drag at scale 1 is averaged by the trapezoid rule over the same ends, and the ratio
D_meas / D_model is filtered, k_rho <- k_rho + K_f (ratio - k_rho).

Units: SI throughout (m, m/s, rad, s, m/s^2, kg/m^3).
"""

import math
from dataclasses import dataclass
from typing import Protocol

from aotv_cosim.guidance import npc_kernel
from aotv_cosim.physics import orbit, point_mass
from aotv_cosim.physics.atmosphere import exponential_density
from aotv_cosim.physics.constants import (
    CD0_000, G0, H_SCALE_000, M_OVER_S_000, MU_EARTH, R_EARTH_000, RHO_S_000,
)
from aotv_cosim.physics.planar import EXIT_000

TARGET_APOGEE_000 = orbit.apsis_altitudes(*EXIT_000)[1]
"""Apogee altitude of the orbit through the Table 4.1 exit state (90 km, 8150 m/s, 0.0144 rad),
m: 1191.154 km (seed-000 extraction Sec. 5 [D]: 1191.15 km), the LEO of the transfer."""


@dataclass(frozen=True)
class PredictorModel:
    """The vehicle and planet the predictor integrates (they must match the vehicle FMU's).

    rho_ref kg/m^3 at h_ref m, scale_height m (eq. 2.5); cd_s_m = C_D0 / (m/S), m^2/kg (eq. 2.6);
    r_earth m; gravity_model and g0 m/s^2, mu m^3/s^2 as in `point_mass.gravity`.
    """

    rho_ref: float = RHO_S_000
    h_ref: float = 0.0
    scale_height: float = H_SCALE_000
    cd_s_m: float = CD0_000 / M_OVER_S_000
    r_earth: float = R_EARTH_000
    gravity_model: int = point_mass.GRAVITY_CONSTANT
    g0: float = G0
    mu: float = MU_EARTH

    def density(self, h: float, scale: float) -> float:
        """Model density scale * rho(h), kg/m^3 (eq. 2.5)."""
        return scale * exponential_density(h, self.rho_ref, self.h_ref, self.scale_height)

    def drag(self, h: float, v: float, scale: float) -> float:
        """Model drag specific force D/m = rho v^2 C_D0 / (2 m/S), m/s^2 (eq. 2.6)."""
        return 0.5 * self.density(h, scale) * v * v * self.cd_s_m


@dataclass(frozen=True)
class NpcSettings:
    """Guidance parameters.

    apogee_target: target apogee altitude h_a*, m; h_exit: atmospheric interface, m; tolerance:
    accepted |apogee miss|, m; max_iter: predictions per cycle; step: predictor RK4 step, s;
    horizon: longest prediction, s; h_floor: a prediction below this altitude counts as not
    exiting, m; u_min, u_max: bounds of the corrected command, m/s^2; t_switch: end of phase 1
    (elapsed time), s; u_final: level of the phase-1 profile at t_switch, m/s^2; du_secant: size
    of the first secant step, m/s^2.
    """

    apogee_target: float = TARGET_APOGEE_000
    h_exit: float = EXIT_000[0]
    tolerance: float = 100.0
    max_iter: int = 8
    step: float = 2.0
    horizon: float = 600.0
    h_floor: float = 40e3
    u_min: float = -3.0
    u_max: float = 3.0
    t_switch: float = 300.0
    u_final: float = 0.0
    du_secant: float = 0.02
    du_max: float = 0.25


@dataclass(frozen=True)
class Prediction:
    """One predicted trajectory: exited (crossed h_exit climbing), time of the crossing or of the
    end of the prediction (elapsed s), the state there (h m, v m/s, gamma rad), the apogee
    altitude of its orbit (m; inf when unbound) and the miss apogee - target (m; inf when
    unbound). A prediction that does not exit ends at h_floor or at the horizon."""

    exited: bool
    time: float
    h: float
    v: float
    gamma: float
    apogee: float
    miss: float

    def usable(self) -> bool:
        """The miss is a number the secant can use: the vehicle exits on a bound orbit."""
        return self.exited and math.isfinite(self.miss)


@dataclass(frozen=True)
class Correction:
    """Result of one guidance cycle: the corrected command u_c (m/s^2), the prediction flown with
    it, the number of predictions made and whether |miss| <= tolerance."""

    u_c: float
    prediction: Prediction
    iterations: int
    converged: bool


def lift_profile(t: float, t_k: float, u_c: float, s: NpcSettings) -> float:
    """Lift acceleration u(t) (m/s^2) of the profile with parameter u_c set at cycle time t_k (s);
    times are elapsed since the start. Phase 1 (t_k < t_switch): linear from u_c at t_k to
    u_final at t_switch, u_final afterwards; phase 2 (t_k >= t_switch): constant u_c."""
    if t_k >= s.t_switch:
        return u_c
    if t >= s.t_switch:
        return s.u_final
    return u_c + (s.u_final - u_c) * (t - t_k) / (s.t_switch - t_k)


def profile_mean(t0: float, t1: float, t_k: float, u_c: float, s: NpcSettings) -> float:
    """Mean of `lift_profile` over [t0, t1] (s, elapsed; t1 > t0), m/s^2: the constant command
    that gives the vehicle, which holds its input over a communication step, the profile's
    integral over that step. Exact for the piecewise-linear profile (split at t_switch)."""
    def integral(a, b):  # each piece is linear: trapezoid rule is exact
        return 0.5 * (b - a) * (lift_profile(a, t_k, u_c, s) + lift_profile(b, t_k, u_c, s))

    if t0 < s.t_switch < t1 and t_k < s.t_switch:
        return (integral(t0, s.t_switch) + integral(s.t_switch, t1)) / (t1 - t0)
    return integral(t0, t1) / (t1 - t0)


def fly(t_k: float, state, u_c: float, scale: float, model: PredictorModel,
        s: NpcSettings) -> tuple[bool, float, float, float, float]:
    """(exited, time s, h m, v m/s, gamma rad) of the predictor's flight from the state (h m,
    v m/s, gamma rad) at elapsed time t_k (s): classical RK4 steps of `s.step` of the vehicle
    FMU's equations (`point_mass.derivatives` in the plane, bank 0; the downrange angle, which
    nothing here depends on, is left out) with the density `model.density(h, scale)` and the lift
    `lift_profile` taken at every stage, until the altitude climbs through h_exit (the crossing
    interpolated linearly inside the step: exited), falls below h_floor, or the horizon ends.

    The same operations in the same order as those functions, written out in floats (the
    predictor is 90 % of an NPC run), so the same numbers to the bit (`tests/studies/test_npc_kernel.py`
    compares with RK4 on `point_mass.derivatives`). Where a C compiler is found, `npc_kernel` runs
    this loop compiled, about 20 times faster (a prediction 45 us against 0.9 ms in floats and
    3 ms for the six-state RK4 of `point_mass.derivatives` it replaces, measured on one machine).
    """
    compiled = npc_kernel.flight((t_k, *state, u_c, scale, model.rho_ref, model.h_ref, model.scale_height,
                                  model.cd_s_m, model.r_earth, model.gravity_model, model.g0, model.mu,
                                  s.h_exit, s.step, s.horizon, s.h_floor, s.t_switch, s.u_final))
    if compiled is not None:
        return compiled
    exp, cos, sin = math.exp, math.cos, math.sin
    r_earth, rho_ref, h_ref, big_h, cd_s_m = model.r_earth, model.rho_ref, model.h_ref, model.scale_height, model.cd_s_m
    constant_g, g0, mu = model.gravity_model == point_mass.GRAVITY_CONSTANT, model.g0, model.mu
    t_switch, u_final, step = s.t_switch, s.u_final, s.step

    def lift(t):  # lift_profile
        if t_k >= t_switch:
            return u_c
        if t >= t_switch:
            return u_final
        return u_c + (u_final - u_c) * (t - t_k) / (t_switch - t_k)

    def rates(r, v, gamma, u):  # point_mass._rates' planar branch, lift_acc u, cl_s_m 0
        q_over_m = 0.5 * (scale * (rho_ref * exp(-((r - r_earth) - h_ref) / big_h))) * v * v
        g = g0 if constant_g else mu / (r * r)
        cg, sg = cos(gamma), sin(gamma)
        return v * sg, -(q_over_m * cd_s_m) - g * sg, (u + q_over_m * 0.0 - (g - v * (v / r)) * cg) / v

    h0, v, gamma = state
    r = r_earth + h0
    t, t_end = t_k, t_k + s.horizon
    h_exit_r, floor_r = r_earth + s.h_exit, r_earth + s.h_floor
    while t < t_end:
        dt = min(step, t_end - t)
        half = 0.5 * dt
        u_half = lift(t + half)
        a0, a1, a2 = rates(r, v, gamma, lift(t))
        b0, b1, b2 = rates(r + half * a0, v + half * a1, gamma + half * a2, u_half)
        c0, c1, c2 = rates(r + half * b0, v + half * b1, gamma + half * b2, u_half)
        d0, d1, d2 = rates(r + dt * c0, v + dt * c1, gamma + dt * c2, lift(t + dt))
        sixth = dt / 6.0
        r_new = r + sixth * (a0 + 2.0 * b0 + 2.0 * c0 + d0)
        v_new = v + sixth * (a1 + 2.0 * b1 + 2.0 * c1 + d1)
        gamma_new = gamma + sixth * (a2 + 2.0 * b2 + 2.0 * c2 + d2)
        if r_new >= h_exit_r > r and gamma_new > 0.0:
            f = (h_exit_r - r) / (r_new - r)
            return True, t + f * dt, s.h_exit, v + f * (v_new - v), gamma + f * (gamma_new - gamma)
        t, r, v, gamma = t + dt, r_new, v_new, gamma_new
        if r < floor_r:
            break
    return False, t, r - r_earth, v, gamma


def _prediction(exited, t, h, v, gamma, model, s):
    if 0.5 * v * v >= model.mu / (model.r_earth + h):
        return Prediction(exited, t, h, v, gamma, math.inf, math.inf)
    apogee = orbit.apsis_altitudes(h, v, gamma, model.mu, model.r_earth)[1]
    return Prediction(exited, t, h, v, gamma, apogee, apogee - s.apogee_target)


def predict(t_k: float, state, u_c: float, scale: float, model: PredictorModel,
            s: NpcSettings) -> Prediction:
    """Fly the model from the measured state (h m, v m/s, gamma rad) at elapsed time t_k (s) under
    the profile with parameter u_c and density scale `scale`, until the altitude climbs through
    h_exit (interpolated linearly inside the step), falls below h_floor, or the horizon ends."""
    h0, v0, gamma0 = state
    if h0 >= s.h_exit and gamma0 > 0.0:  # already out, climbing: the exit is now
        return _prediction(True, t_k, h0, v0, gamma0, model, s)
    return _prediction(*fly(t_k, state, u_c, scale, model, s), model, s)


def _clip(u, s):
    return min(max(u, s.u_min), s.u_max)


def bracket(x: float, f: float, low, high, side: int):
    """(low, high, side): the Illinois bracket of a root after the trial (x, f(x)); low and high are
    [x, f] lists or None, side the sign of the last trial's f (the end kept twice in a row has its
    f halved, so the regula falsi candidate leaves it)."""
    if f > 0.0:
        if side > 0 and low is not None:
            low[1] *= 0.5
        return low, [x, f], 1
    if side < 0 and high is not None:
        high[1] *= 0.5
    return [x, f], high, -1


def _secant(u, f, prev, s: NpcSettings) -> float:
    """Secant step from (u, f) through the last usable iterate prev, at most du_max long; a first
    step of du_secant without prev or when the two points do not show the apogee growing with u."""
    if prev is not None and u != prev[0]:
        slope = (f - prev[1]) / (u - prev[0])
        if slope > 0.0:
            step = -f / slope
            return u + max(-s.du_max, min(s.du_max, step))
    return u - math.copysign(s.du_secant, f)


def correct(t_k: float, state, u_guess: float, scale: float, model: PredictorModel,
            s: NpcSettings) -> Correction:
    """Secant corrector of one guidance cycle: u_c with |apogee miss| <= tolerance, from u_guess.

    The apogee grows with u_c. Until two iterates bracket the root, secant steps (eq. in the
    module docstring) at most du_max long; a prediction that does not exit counts as too low and
    an unbound one as too high, and moves the next iterate by du_max the way that cures it. Once
    bracketed: false position between the bracket ends with the Illinois modification (the
    retained end's miss is halved when the same end is retained twice); if an end's miss is not
    a number, the secant step when it stays inside the bracket, else bisection. u_c stays in [u_min, u_max]. At the
    iteration limit the iterate with the smallest usable miss is returned, converged False.
    """
    u = _clip(u_guess, s)
    pred = predict(t_k, state, u, scale, model, s)
    iterations = 1
    if pred.exited and pred.time == t_k:  # out of the atmosphere: nothing left to correct
        return Correction(u, pred, iterations, pred.usable() and abs(pred.miss) <= s.tolerance)
    best = (u, pred)
    low = high = None  # [u, miss] with miss < 0 (or no exit: -inf) and miss > 0 (or unbound: inf)
    prev, side = None, 0
    while True:
        f = pred.miss if pred.exited else -math.inf
        usable = pred.usable()
        if usable and (not best[1].usable() or abs(f) < abs(best[1].miss)):
            best = (u, pred)
        if usable and abs(f) <= s.tolerance:
            return Correction(u, pred, iterations, True)
        if iterations >= s.max_iter:
            break
        low, high, side = bracket(u, f, low, high, side)
        if low is not None and high is not None:
            if math.isfinite(low[1]) and math.isfinite(high[1]):
                candidate = low[0] - low[1] * (high[0] - low[0]) / (high[1] - low[1])
            else:
                candidate = _secant(u, f, prev, s) if usable else math.nan
                if not low[0] < candidate < high[0]:  # also when nan
                    candidate = 0.5 * (low[0] + high[0])
        elif usable:
            candidate = _secant(u, f, prev, s)
        else:
            candidate = u + (s.du_max if f < 0.0 else -s.du_max)
        candidate = _clip(candidate, s)
        if usable:
            prev = (u, f)
        if candidate == u:
            break  # pinned at a bound, or the bracket has closed on u
        u = candidate
        pred = predict(t_k, state, u, scale, model, s)
        iterations += 1
    u, pred = best
    return Correction(u, pred, iterations, False)


class DragModel(Protocol):
    """What `measured_density_ratio` reads of a model: `PredictorModel`, `npc_bank.BankModel`."""

    @property
    def r_earth(self) -> float: ...
    @property
    def gravity_model(self) -> int: ...
    @property
    def g0(self) -> float: ...
    @property
    def mu(self) -> float: ...
    def drag(self, h: float, v: float, scale: float) -> float: ...


def measured_density_ratio(sample0, sample1, model: DragModel) -> float:
    """Density scale seen between two navigated samples (t s, h m, v m/s, gamma rad): the mean
    drag -(v1 - v0)/dt - g (sin gamma0 + sin gamma1)/2 (from eq. 2.7) over the trapezoidal mean
    of the model drag at scale 1 at the two samples, dimensionless; nan if dt <= 0."""
    t0, h0, v0, g0_ = sample0
    t1, h1, v1, g1_ = sample1
    dt = t1 - t0
    if not dt > 0.0:
        return math.nan
    grav0 = point_mass.gravity(model.r_earth + h0, model.gravity_model, model.g0, model.mu)
    grav1 = point_mass.gravity(model.r_earth + h1, model.gravity_model, model.g0, model.mu)
    drag = -(v1 - v0) / dt - 0.5 * (grav0 * math.sin(g0_) + grav1 * math.sin(g1_))
    return drag / (0.5 * (model.drag(h0, v0, 1.0) + model.drag(h1, v1, 1.0)))


def filter_density_scale(previous: float, measured: float, gain: float) -> float:
    """First-order fading-memory filter k <- k + gain (measured - k); a non-finite or non-positive
    measurement leaves k unchanged (gain in [0, 1])."""
    if not (math.isfinite(measured) and measured > 0.0):
        return previous
    return previous + gain * (measured - previous)


@dataclass(frozen=True)
class NpcMemory:
    """What the guidance keeps between cycles: the last navigated sample (t s, h m, v m/s,
    gamma rad) or None, the filtered density scale k_rho, and the last corrected command u_c
    (m/s^2) with its cycle time t_k (s; None before the first cycle)."""

    sample: tuple | None = None
    scale: float = 1.0
    u_c: float = 0.0
    t_k: float | None = None


def guidance_cycle(memory: NpcMemory, t: float, state, model: PredictorModel, s: NpcSettings,
                   gain: float):
    """One guidance cycle at elapsed time t (s) from the measured state (h m, v m/s, gamma rad):
    update the density scale from the drag seen since the last sample (`measured_density_ratio`,
    `filter_density_scale` with `gain`), then correct u_c warm-started from the last cycle.
    Returns (the memory after the cycle, the Correction)."""
    sample = (t, *state)
    scale = memory.scale
    if memory.sample is not None:
        scale = filter_density_scale(scale, measured_density_ratio(memory.sample, sample, model), gain)
    corr = correct(t, state, memory.u_c, scale, model, s)
    return NpcMemory(sample, scale, corr.u_c, t), corr
