"""Numerical predictor-corrector aerocapture guidance by bank angle (FNPAG-like).

The bank-angle form of `guidance.npc` for a vehicle at trim (Lu, Cerimele, Tigges & Matz,
"Optimal aerocapture guidance", JGCD 38(4), 2015, FNPAG; Matz, Lu, Mendeck & Sostaric,
"Application of a fully numerical guidance to Mars aerocapture", AIAA 2017-1901):

Predictor. From the measured state (h, v, gamma) at elapsed time t_k, the planar equations of
motion of the vehicle FMU (`physics.point_mass.derivatives`, inverse-square gravity) are integrated
by RK4 to the exit crossing (h_exit, climbing; linear interpolation in the step) with the vehicle's
own model: lift and drag from one density, L/m = q C_L S/m cos sigma, D/m = q C_D S/m, the density
the Atmosphere FMU's model (US76 `physics.us76` or exponential) times the estimated scale k_rho.

Profile (one parameter, the vertical lift fraction x = cos|sigma|):
    constant:   |sigma(t)| = arccos x for the rest of the pass;
    two-phase:  |sigma| = arccos x until t_switch (elapsed s), then |sigma_2| (the exit phase of
                FNPAG, which flies a fixed bank after its switch; here a parameter), and after
                t_switch the constant form with x re-solved.
The predicted exit apogee grows with x, steeply near the corridor's edges (for the AFE class
about 30 km of apogee per 0.001 of x at the nominal entry). Corrector: the miss in inverse apogee
radius, z(x) = 1/r_a* - 1/r_a(x) (r = R_e + h; 1/r_a* for an unbound orbit; for a prediction that
does not exit, r_a of the osculating orbit where it ends, below the target: a finite miss that
keeps growing with x through the edge of the exit region), is zeroed by a safeguarded secant (false position with
the Illinois modification once two iterates bracket the root, steps of at most dx_max before), x
kept in [cos sigma_max, cos sigma_min]. Convergence: an exiting prediction with
|h_a - h_a*| <= tolerance.

Density scale: measured drag over model drag between two cycles, low-pass filtered
(`npc.measured_density_ratio`, `npc.filter_density_scale`): the drag is along the velocity, so
it is read off v_dot whatever the bank. The predictor also flies a scale that depends on
altitude (`ScaleProfile`: the sensed-drag table of `guidance.density_estimation`).

Speed: `fly` runs compiled from C where a compiler is found (`npc_bank_kernel`, the same
operations in the same order, so the same predictions).

Lateral logic: `guidance.lateral` (bank reversals when the plane error leaves a deadband).
Units: SI (m, m/s, rad, s, m/s^2, kg/m^3).
"""

import bisect
import math
import operator
from dataclasses import dataclass
from functools import cached_property

from aotv_cosim.guidance import npc, npc_bank_kernel
from aotv_cosim.physics import orbit, point_mass, us76
from aotv_cosim.physics.atmosphere import exponential_density
from aotv_cosim.physics.constants import MU_EARTH, R_EARTH_000

ATMOSPHERE_EXPONENTIAL, ATMOSPHERE_US76 = 0, 1


@dataclass(frozen=True)
class ScaleProfile:
    """A density scale that depends on altitude: k(h) piecewise linear through the nodes
    (altitudes m, strictly ascending; scales, dimensionless), the end values held outside them."""

    altitudes: tuple
    scales: tuple

    def __post_init__(self):
        if not self.scales or len(self.altitudes) != len(self.scales):
            raise ValueError("a ScaleProfile needs as many altitudes as scales, at least one")
        if not all(map(operator.lt, self.altitudes, self.altitudes[1:])):
            raise ValueError("ScaleProfile altitudes must be strictly ascending")

    def at(self, h: float) -> float:
        """k(h), h in m."""
        a, k = self.altitudes, self.scales
        if len(a) == 1 or h <= a[0]:
            return k[0]
        if h >= a[-1]:
            return k[-1]
        j = bisect.bisect_right(a, h) - 1
        return k[j] + (k[j + 1] - k[j]) * (h - a[j]) / (a[j + 1] - a[j])

    @cached_property
    def kernel_nodes(self):
        """The nodes as the compiled predictor takes them (`npc_bank_kernel.scale_arrays`), built
        once per profile: a cycle flies one profile several times."""
        return npc_bank_kernel.scale_arrays(self.altitudes, self.scales)


@dataclass(frozen=True)
class BankModel:
    """The vehicle and planet the predictor flies (they must match the FMUs'): cl_s_m = C_L S/m
    and cd_s_m = C_D S/m (m^2/kg); atmosphere ATMOSPHERE_US76 or ATMOSPHERE_EXPONENTIAL with
    rho_ref (kg/m^3) at h_ref (m) and scale_height (m); r_earth m, mu m^3/s^2 (inverse-square
    gravity: gravity_model 1)."""

    cl_s_m: float
    cd_s_m: float
    atmosphere: int = ATMOSPHERE_US76
    rho_ref: float = 1.225
    h_ref: float = 0.0
    scale_height: float = 7000.0
    r_earth: float = R_EARTH_000
    mu: float = MU_EARTH
    gravity_model: int = point_mass.GRAVITY_INVERSE_SQUARE
    g0: float = 9.80665

    @classmethod
    def of(cls, vehicle, **planet) -> "BankModel":
        """The model of a vehicle at trim (C_L `cl`, C_D `cd`, reference area `s_ref` m^2, `mass`
        kg: a `physics.aerocapture_vehicles.TrimVehicle`), US76 and inverse-square gravity unless
        `planet` says otherwise."""
        return cls(vehicle.cl * vehicle.s_ref / vehicle.mass, vehicle.cd * vehicle.s_ref / vehicle.mass, **planet)

    def density(self, h: float, scale) -> float:
        """Model density k * rho(h), kg/m^3, with k the density scale: a number, or a
        `ScaleProfile` evaluated at h."""
        k = scale.at(h) if isinstance(scale, ScaleProfile) else scale
        if self.atmosphere == ATMOSPHERE_US76:
            return k * us76.density(h)
        return k * exponential_density(h, self.rho_ref, self.h_ref, self.scale_height)

    def drag(self, h: float, v: float, scale: float) -> float:
        """Model drag specific force q C_D S/m, m/s^2."""
        return 0.5 * self.density(h, scale) * v * v * self.cd_s_m


@dataclass(frozen=True)
class BankSettings:
    """apogee_target, h_exit, tolerance, h_floor in m; max_iter predictions per cycle; step, horizon
    in s (predictor RK4 step, longest prediction); sigma_min, sigma_max bound |sigma| (rad);
    t_switch (elapsed s; inf: constant profile) and sigma_2 (rad) of the two-phase profile;
    dx_secant, dx_max: first and longest corrector steps in x = cos|sigma|."""

    apogee_target: float
    h_exit: float
    tolerance: float = 1000.0
    max_iter: int = 12
    step: float = 2.0
    horizon: float = 900.0
    h_floor: float = 30e3
    sigma_min: float = 0.0
    sigma_max: float = math.pi
    t_switch: float = math.inf
    sigma_2: float = 0.0
    dx_secant: float = 0.02
    dx_max: float = 0.5

    @property
    def x_bounds(self):
        """(lowest, highest) vertical lift fraction cos|sigma|."""
        return math.cos(self.sigma_max), math.cos(self.sigma_min)


def vertical_fraction(t: float, x: float, s: BankSettings) -> float:
    """cos|sigma| of the profile with parameter x at elapsed time t (s)."""
    return math.cos(s.sigma_2) if t >= s.t_switch else x


def _rates(t, y, x, scale, model, s):
    """Planar (r, v, gamma) rates of `point_mass.derivatives` with the model's lift and drag."""
    r, v, gamma = y
    rho = model.density(r - model.r_earth, scale)
    q = 0.5 * rho * v * v
    g = point_mass.gravity(r, model.gravity_model, model.g0, model.mu)
    cg = math.cos(gamma)
    lift = q * model.cl_s_m * vertical_fraction(t, x, s)
    return v * math.sin(gamma), -q * model.cd_s_m - g * math.sin(gamma), (lift - (g - v * v / r) * cg) / v


def _rk4(t, y, dt, x, scale, model, s):
    k1 = _rates(t, y, x, scale, model, s)
    k2 = _rates(t + 0.5 * dt, [a + 0.5 * dt * b for a, b in zip(y, k1)], x, scale, model, s)
    k3 = _rates(t + 0.5 * dt, [a + 0.5 * dt * b for a, b in zip(y, k2)], x, scale, model, s)
    k4 = _rates(t + dt, [a + dt * b for a, b in zip(y, k3)], x, scale, model, s)
    return [a + dt / 6.0 * (p + 2.0 * q + 2.0 * r + w) for a, p, q, r, w in zip(y, k1, k2, k3, k4)]


def _prediction(exited, t, h, v, gamma, model, s):
    if 0.5 * v * v >= model.mu / (model.r_earth + h):
        return npc.Prediction(exited, t, h, v, gamma, math.inf, math.inf)
    apogee = orbit.apsis_altitudes(h, v, gamma, model.mu, model.r_earth)[1]
    return npc.Prediction(exited, t, h, v, gamma, apogee, apogee - s.apogee_target)


def fly(t_k: float, state, x: float, scale, model: BankModel,
        s: BankSettings) -> tuple[bool, float, float, float, float]:
    """(exited, time s, h m, v m/s, gamma rad) of the model flown from state (h m, v m/s,
    gamma rad) at elapsed t_k (s) with vertical lift fraction x and density scale `scale` (a
    number or a `ScaleProfile`): RK4 steps of s.step (`_rk4`) until the altitude climbs through
    h_exit (the crossing interpolated linearly in the step: exited), falls below h_floor, or the
    horizon ends. Where a C compiler is found, `npc_bank_kernel` runs this loop compiled, the
    same operations in the same order (the same numbers to the bit,
    `tests/studies/test_npc_bank_kernel.py`)."""
    nodes = scale.kernel_nodes if isinstance(scale, ScaleProfile) else npc_bank_kernel.scale_arrays((0.0,), (scale,))
    compiled = npc_bank_kernel.flight(
        (t_k, *state, x, model.cl_s_m, model.cd_s_m, model.atmosphere, model.rho_ref, model.h_ref,
         model.scale_height, model.r_earth, model.gravity_model, model.g0, model.mu, s.h_exit, s.step,
         s.horizon, s.h_floor, s.t_switch, math.cos(s.sigma_2)), nodes)
    if compiled is not None:
        return compiled
    h0, v0, gamma0 = state
    y = [model.r_earth + h0, v0, gamma0]
    t, t_end = t_k, t_k + s.horizon
    exit_r, floor_r = model.r_earth + s.h_exit, model.r_earth + s.h_floor
    while t < t_end:
        dt = min(s.step, t_end - t)
        y_new = _rk4(t, y, dt, x, scale, model, s)
        if y_new[0] >= exit_r > y[0] and y_new[2] > 0.0:
            f = (exit_r - y[0]) / (y_new[0] - y[0])
            return True, t + f * dt, s.h_exit, y[1] + f * (y_new[1] - y[1]), y[2] + f * (y_new[2] - y[2])
        t, y = t + dt, y_new
        if y[0] < floor_r:
            break
    return False, t, y[0] - model.r_earth, y[1], y[2]


def predict(t_k: float, state, x: float, scale, model: BankModel, s: BankSettings) -> npc.Prediction:
    """Fly the model from state (h m, v m/s, gamma rad) at elapsed t_k (s) with vertical lift
    fraction x and density scale `scale` (a number or a `ScaleProfile`) to the exit crossing,
    h_floor or the horizon (`fly`), and the apogee of the orbit where it ends."""
    h0, v0, gamma0 = state
    if h0 >= s.h_exit and gamma0 > 0.0:
        return _prediction(True, t_k, h0, v0, gamma0, model, s)
    return _prediction(*fly(t_k, state, x, scale, model, s), model, s)


def correct(t_k: float, state, x_guess: float, scale, model: BankModel, s: BankSettings) -> npc.Correction:
    """x = cos|sigma| with |apogee miss| <= tolerance (module docstring), from x_guess; at the
    iteration limit the exiting iterate with the smallest apogee miss, converged False. The
    Correction's u_c field holds x."""
    lo_x, hi_x = s.x_bounds
    x = min(max(x_guess, lo_x), hi_x)
    pred = predict(t_k, state, x, scale, model, s)
    iterations, best = 1, (x, pred)
    low = high = None  # [x, miss] bracketing the root
    prev, side = None, 0
    target_r = model.r_earth + s.apogee_target
    while True:
        f = 1.0 / target_r - 1.0 / (model.r_earth + pred.apogee)
        f = f if pred.exited or f < 0.0 else -math.inf
        usable = math.isfinite(f)
        if usable and (not best[1].exited or abs(pred.miss) < abs(best[1].miss)):
            best = (x, pred)
        if pred.usable() and abs(pred.miss) <= s.tolerance:
            return npc.Correction(x, pred, iterations, True)
        if iterations >= s.max_iter:
            break
        low, high, side = npc.bracket(x, f, low, high, side)
        if low is not None and high is not None:
            if math.isfinite(low[1]) and math.isfinite(high[1]):
                candidate = low[0] - low[1] * (high[0] - low[0]) / (high[1] - low[1])
            else:
                candidate = 0.5 * (low[0] + high[0])
        elif usable and prev is not None and x != prev[0] and (f - prev[1]) / (x - prev[0]) > 0.0:
            step = -f * (x - prev[0]) / (f - prev[1])
            candidate = x + max(-s.dx_max, min(s.dx_max, step))
        elif usable:
            candidate = x - math.copysign(s.dx_secant, f)
        else:
            candidate = x + (s.dx_max if f < 0.0 else -s.dx_max)
        candidate = min(max(candidate, lo_x), hi_x)
        if usable:
            prev = (x, f)
        if candidate == x:
            break
        x = candidate
        pred = predict(t_k, state, x, scale, model, s)
        iterations += 1
    x, pred = best
    return npc.Correction(x, pred, iterations, False)


def guidance_cycle(memory: npc.NpcMemory, t: float, state, model: BankModel, s: BankSettings, gain: float):
    """One cycle at elapsed t (s): density scale update, then `correct` warm-started from the last
    x (memory.u_c holds x). Returns (memory after the cycle, Correction)."""
    sample = (t, *state)
    scale = memory.scale
    if memory.sample is not None:
        scale = npc.filter_density_scale(scale, npc.measured_density_ratio(memory.sample, sample, model), gain)
    corr = correct(t, state, memory.u_c, scale, model, s)
    return npc.NpcMemory(sample, scale, corr.u_c, t), corr


def cycle_with_scale(memory: npc.NpcMemory, t: float, state, scale, model: BankModel, s: BankSettings):
    """One cycle at elapsed t (s) with a density scale estimated elsewhere (a number or a
    `ScaleProfile`): `correct` warm-started from the last x. Returns (memory after the cycle,
    with the scale at the present altitude, Correction)."""
    corr = correct(t, state, memory.u_c, scale, model, s)
    here = scale.at(state[0]) if isinstance(scale, ScaleProfile) else scale
    return npc.NpcMemory((t, *state), here, corr.u_c, t), corr
