"""Per-run oracle of bank-angle aerocapture: the minimum-dv pass of a run, found with its truth.

The minimum-dv aerocapture flies a bank profile of two arcs, full lift up, then, from a switch
time, lift down (Lu, Cerimele, Tigges & Matz, "Optimal aerocapture guidance", JGCD 38(4), 2015,
whose FNPAG flies a constant bank after the switch; Zucchelli & Mooij, "Minimum radiative heat
and propellant aerocapture guidance with attitude kinematics constraints", JGCD 2025, arXiv
2411.03113: "a single switch bang-bang trajectory, starting with lift up"). The oracle knows the
run exactly (vehicle C_L, C_D, S, m; the atmosphere's model density times its scale and random
profile; the bank actuator's limits; the entry state) and flies
    |sigma| = 0 (full lift up) before the switch point t_s,
    |sigma| = sigma_2 (a constant bank, solved so that the exit apogee is on the target) from it,
a family that holds the lift-up-first bang-bang (sigma_2 = pi) and every constant-bank pass
(t_s = 0). Why not the bang-bang alone: on the 400 km target of the aerocapture sets the exit
speed is barely above circular and a full-lift-down exit arc either climbs out fast or falls
back: the exit apogee of the lift-up-first bang-bang jumps over the +-10 km capture band as t_s
moves by a microsecond; the lift-down-first bang-bang is admissible and costs far more dv than a
constant bank (docs/benchmark.md, "The oracle"). The dv falls as the switch moves later and the
exit arc turns toward lift down, to the latest switch at which the target can still be met:
that is the pass the search looks for.

Predictor: the co-simulated pass itself, step for step as the master flies the sets (step
`command_period`, Gauss-Seidel in the order vehicle, atmosphere, guidance, actuator, delayed
inputs extrapolated): the vehicle FMU's RK4 (`point_mass`) with the density and bank held over
each step at the master's extrapolation of their last two values, the density of the
Atmosphere FMU (`TruthModel.density`), the bank of the BankActuator FMU (`bank_actuator.step`)
following the command the guidance gives at the end of the step, the exit where the master
locates it (linear interpolation of the step that crosses h_exit climbing). So the flown pass is
the predicted one (the same operations: the same numbers). The continuous equations of motion
would not do: the long exit arcs of these passes hold the vehicle near the top of the
atmosphere for minutes, where a relative difference of 1e-4 in the density of a step
(continuous against held) decides whether it climbs out (docs/benchmark.md). Where a C compiler
is found the prediction runs compiled (`oracle_kernel`: the same operations in the same order, so
the same plans to the bit, 15-18 times cheaper); the Python loop `_fly_python` is the fallback.

Search: the pass flown at full lift up is recorded at every communication point; a switch at
the point k starts from it. The latest point k from which the exit arc at sigma_2_max still
brings the apogee down to the target is found by bisection (one prediction each); there the exit
bank is solved (`solve_exit_bank`). A pass is admissible when its apogee is within `accept` of
the target and it exits `horizon_margin` before the run's end; when the solved pass is not (its
apogee jumps over the band, or it lasts too long), the switch steps back by `walk` points until
one is, then bisection between the two. Without any, the constant bank (point 0).
The plane is held by bank reversals (`guidance.lateral`, deadband 1 deg by default, twice the bank
laws' 0.5 deg: the apogee jumps with each reversal that moves by a step, and with 0.5 deg one
AOTV solve in six found no admissible pass).
Units: SI (m, m/s, rad, s, kg/m^3).
"""

import math
from typing import Any
from dataclasses import dataclass
from functools import lru_cache

from aotv_cosim.guidance import lateral, oracle_kernel
from aotv_cosim.guidance.npc import bracket
from aotv_cosim.physics import bank_actuator, density_profile, orbit, point_mass
from aotv_cosim.physics.atmosphere import model_density
from aotv_cosim.physics.constants import G0, MU_EARTH, R_EARTH_000
from aotv_cosim.physics.density_profile import profile_factor
from aotv_cosim.physics.orbit_correction import circularization_corrections

LIFT_DOWN = math.pi - 1e-9
"""Bank of full lift down, rad: cos is -1 to the last bit, and a turn to or from it takes the short
way without crossing +-pi, where the actuator's angle wraps (the master's linear extrapolation of
a wrapped angle would fly one wrong step)."""
JUMP = 1e-7
"""Narrowest bracket of the exit bank's corrector in x = cos sigma_2: the apogee moves by up to
1e6 km per unit of x, so a bracket this narrow that still holds the target is a jump."""
FIRST_STEP = 0.005
"""First step of the exit bank's corrector in x = cos sigma_2: a warm start is usually within it,
and the apogee moves by 1e4 to 1e6 km per unit of x."""


@dataclass(frozen=True)
class TruthModel:
    """The run as it is: cl_s_m = C_L S/m, cd_s_m = C_D S/m (m^2/kg); the Atmosphere FMU's
    atmosphere_model (0 exponential with rho_ref kg/m^3 at h_ref m and scale_height m, 1 US76),
    density_factor (1), profile_sigma (1), profile_length (m), profile_seed (its integer part);
    the bank actuator's rate_limit (rad/s) and accel_limit (rad/s^2); r_earth (m), mu (m^3/s^2)."""

    cl_s_m: float
    cd_s_m: float
    density_factor: float = 1.0
    profile_sigma: float = 0.0
    profile_length: float = 10000.0
    profile_seed: float = 0.0
    atmosphere_model: int = 1
    rho_ref: float = 1.225
    h_ref: float = 0.0
    scale_height: float = 7000.0
    rate_limit: float = math.radians(20.0)
    accel_limit: float = math.radians(5.0)
    r_earth: float = R_EARTH_000
    mu: float = MU_EARTH

    def density(self, h: float) -> float:
        """Density at altitude h (m), kg/m^3, as the Atmosphere FMU gives it without noise."""
        rho = model_density(self.atmosphere_model, h, self.rho_ref, self.h_ref, self.scale_height)
        return self.density_factor * rho * profile_factor(h, self.profile_sigma, self.profile_length,
                                                          int(self.profile_seed))


@dataclass(frozen=True)
class OracleSettings:
    """apogee_target, h_exit, h_floor in m; tolerance: |apogee - target| (m) that ends a solve;
    accept: |apogee - target| (m) of an admissible pass;
    command_period, horizon (the run's end after the start), horizon_margin in s; deadband: the
    plane-error deadband of the bank reversals (rad, `guidance.lateral`; pi: none);
    input_extrapolation: 1 when the scenario's delayed inputs are extrapolated
    ("inputs": "extrapolated"), 0 when held; max_substep: the vehicle's RK4 substep (s); sigma_2_max:
    the largest exit-arc bank (rad); walk, steps_back: switch points per step back from an
    inadmissible latest switch, and the most steps;
    max_iter: predictions per solve of sigma_2."""

    apogee_target: float
    h_exit: float
    command_period: float = 1.0
    tolerance: float = 1000.0
    accept: float = 8000.0
    h_floor: float = 30e3
    horizon: float = 900.0
    horizon_margin: float = 30.0
    deadband: float = math.radians(1.0)
    input_extrapolation: int = 1
    max_substep: float = 0.5
    sigma_2_max: float = LIFT_DOWN
    walk: int = 3
    steps_back: int = 10
    max_iter: int = 20


@dataclass(frozen=True)
class Pass:
    """A predicted pass: exited (climbed through h_exit), t (s, the exit or where it ended), the
    state (h m, v m/s, gamma rad) there, apogee altitude (m; inf unbound, -inf no exit) and the
    correction dv to the circular target orbit (m/s, nan without a bound exit)."""

    exited: bool
    t: float
    h: float
    v: float
    gamma: float
    apogee: float
    dv_total: float


@dataclass(frozen=True)
class Plan:
    """The oracle's pass: full lift up to t_switch (s after the start, a communication point),
    then the exit arc's bank sigma_2 (rad); its predicted Pass, admissible, the predictions made
    and the solve's CPU time (s, when the caller measures it)."""

    t_switch: float
    sigma_2: float
    prediction: Pass
    admissible: bool
    predictions: int
    solve_cpu: float = math.nan

    def command(self, t: float) -> float:
        """The bank magnitude command (rad) at the communication point t (s after the start)."""
        return 0.0 if t < self.t_switch else self.sigma_2


def _exit_pass(t, h, v, gamma, model, s) -> Pass:
    if 0.5 * v * v >= model.mu / (model.r_earth + h):
        return Pass(True, t, h, v, gamma, math.inf, math.nan)
    perigee, apogee = orbit.apsis_altitudes(h, v, gamma, model.mu, model.r_earth)
    dv1, dv2 = circularization_corrections(model.r_earth + perigee, model.r_earth + apogee,
                                           model.r_earth + s.apogee_target, model.mu)
    return Pass(True, t, h, v, gamma, apogee, dv1 + dv2)


def _actuator(sigma, rate, cmd, dt, model):
    """The BankActuator FMU's (sigma, rate) after dt toward cmd; at rest on the command it stays."""
    if rate == 0.0 and sigma == cmd:
        return sigma, rate
    return bank_actuator.step(sigma, rate, cmd, dt, model.rate_limit, model.accel_limit)


def _rk4(r, v, gamma, h, rho, cos_sigma, cl, cd, mu):
    """(r, v, gamma) after one RK4 step of h (s) with rho and the bank held: the vehicle FMU's
    `point_mass.rk4_step`, its r, v, gamma rates written in the same operations (they do not
    depend on the other three states), so the same numbers."""
    half = 0.5 * h

    def rates(r, v, gamma):
        q = 0.5 * rho * v * v
        g = mu / (r * r)
        cg, sg = math.cos(gamma), math.sin(gamma)
        return v * sg, -(q * cd) - g * sg, (q * cl * cos_sigma - (g - v * (v / r)) * cg) / v

    a0, a1, a2 = rates(r, v, gamma)
    b0, b1, b2 = rates(r + half * a0, v + half * a1, gamma + half * a2)
    c0, c1, c2 = rates(r + half * b0, v + half * b1, gamma + half * b2)
    d0, d1, d2 = rates(r + h * c0, v + h * c1, gamma + h * c2)
    w = h / 6.0
    return (r + w * (a0 + 2.0 * b0 + 2.0 * c0 + d0), v + w * (a1 + 2.0 * b1 + 2.0 * c1 + d1),
            gamma + w * (a2 + 2.0 * b2 + 2.0 * c2 + d2))


def _vehicle(x, period, args, s: OracleSettings):
    """The vehicle FMU's state after a communication step (`point_mass.integrate` with `args`
    held). Without reversals (deadband pi) the bank's sign never depends on the plane, and r, v,
    gamma do not depend on the other states: only they are integrated, by `_rk4` (the same
    numbers, a third of the work); theta, phi, psi are then not followed."""
    if s.deadband < math.pi:
        return point_mass.integrate(x, period, s.max_substep, args)
    n = max(1, math.ceil(period / s.max_substep - 1e-9))
    r, v, gamma = x[0], x[3], x[4]
    rho, cos_sigma, cl, cd, mu = args[0], math.cos(args[4]), args[2], args[3], args[7]
    for _ in range(n):
        r, v, gamma = _rk4(r, v, gamma, period / n, rho, cos_sigma, cl, cd, mu)
    return (r, x[1], x[2], v, gamma, x[5])


def entry_state(state, model: TruthModel):
    """The `fly` start of the measured entry state (h m, v m/s, gamma rad, phi rad, psi rad) at
    the communication point 0: the vehicle FMU's state (r, theta, phi, v, gamma, psi) with
    theta = 0 (it does not enter the dynamics), the actuator at rest, the bank's sign +1."""
    h0, v0, gamma0, phi0, psi0 = state
    return (0, (model.r_earth + h0, 0.0, phi0, v0, gamma0, psi0), 0.0, 0.0, None, None, 1)


def fly(start, s1: float, t_switch: float, sigma_2: float, model: TruthModel, s: OracleSettings,
        record=None) -> Pass:
    """Fly the co-simulated pass from `start` = (k, vehicle state, sigma rad, rate rad/s, sigma one
    point earlier, density one point earlier (kg/m^3; both None at the point 0), sign of the bank),
    the state at the communication point k, with the bank magnitude s1 before t_switch (s) and
    sigma_2 from it. With `record` (a list), append the start of every step flown. Each step as
    the master steps the sets' components (Gauss-Seidel in their order, module docstring): the
    vehicle (`point_mass.integrate`, the FMU's code) with the density and bank held over the step
    (with input_extrapolation, from the second step on, v_k + (v_k - v_k-1) / 2 of each), then
    the oracle's bank sign (`lateral.bank_sign` on the new plane error) and command, then the
    actuator toward that command. From the point 0 the actuator starts at rest on the first
    command, as the BankActuator FMU does when initialization ends. Where a C compiler is found,
    `oracle_kernel` flies this loop compiled (`_fly_python` with the same operations in the same
    order: the same numbers to the bit, `tests/studies/test_oracle_kernel.py`)."""
    compiled = _fly_compiled(start, s1, t_switch, sigma_2, model, s, record)
    if compiled is not None:
        return compiled
    return _fly_python(start, s1, t_switch, sigma_2, model, s, record)


@lru_cache(maxsize=8)
def _kernel_inputs(model: TruthModel, s: OracleSettings) -> tuple[Any, Any]:
    """(`oracle_kernel.parameters`, `oracle_kernel.profile_nodes`) of the run's truth and settings."""
    p = oracle_kernel.parameters((
        model.cl_s_m, model.cd_s_m, model.density_factor, model.profile_sigma, model.atmosphere_model,
        model.rho_ref, model.h_ref, model.scale_height, model.rate_limit, model.accel_limit, model.r_earth,
        model.mu, s.command_period, s.h_exit, s.h_floor, s.horizon, s.deadband, s.input_extrapolation,
        s.max_substep, G0, bank_actuator.SUBSTEP, density_profile.GRID_STEP, density_profile.GRID_TOP))
    nodes = (density_profile._nodes(float(model.profile_length), int(model.profile_seed))
             if model.profile_sigma != 0.0 else (1.0, 1.0))  # the factor is 1 without a profile: nodes unread
    return p, oracle_kernel.profile_nodes(nodes)


def _fly_compiled(start, s1, t_switch, sigma_2, model: TruthModel, s: OracleSettings, record):
    """`fly` by `oracle_kernel`, or None without the kernel."""
    if not oracle_kernel.available():
        return None
    k, x, sigma, rate, sigma_before, rho_before, sign = start
    known = rho_before is not None
    packed = (k, *x, sigma, rate, sigma_before if known else 0.0, rho_before if known else 0.0, float(known),
              sign)
    capacity = math.ceil(s.horizon / s.command_period) + 1 if record is not None else 0
    exited, t, h, v, gamma, records = oracle_kernel.flight(*_kernel_inputs(model, s), packed, s1, t_switch,
                                                           sigma_2, capacity)
    if record is not None:
        size = oracle_kernel.START_SIZE
        for j in range(0, len(records), size):
            e = records[j:j + size]
            known = e[11] != 0.0
            record.append((int(e[0]), tuple(e[1:7]), e[7], e[8], e[9] if known else None, e[10] if known else None,
                           int(e[12])))
    if exited:
        return _exit_pass(t, h, v, gamma, model, s)
    return Pass(False, t, h, v, gamma, -math.inf, math.nan)


def _fly_python(start, s1, t_switch, sigma_2, model: TruthModel, s: OracleSettings, record=None) -> Pass:
    """`fly` in Python (the loop `oracle_kernel` compiles)."""
    k, x, sigma, rate, sigma_before, rho_before, sign = start
    if k == 0:
        sigma, rate = sign * (s1 if t_switch > 0.0 else sigma_2), 0.0
    period = s.command_period
    args = [0.0, 0.0, model.cl_s_m, model.cd_s_m, 0.0, point_mass.GRAVITY_INVERSE_SQUARE, G0, model.mu,
            point_mass.HEADING_FULL]
    r_earth = model.r_earth
    while k * period < s.horizon:
        t = k * period
        if record is not None:
            record.append((k, x, sigma, rate, sigma_before, rho_before, sign))
        h = x[0] - r_earth
        rho = model.density(h)
        args[0], args[4] = rho, sigma
        if s.input_extrapolation and rho_before is not None:
            args[0], args[4] = rho + 0.5 * (rho - rho_before), sigma + 0.5 * (sigma - sigma_before)
        x_new = _vehicle(x, period, args, s)
        h_new = x_new[0] - r_earth
        if h < s.h_exit <= h_new:
            f = (s.h_exit - h) / (h_new - h)
            gamma_exit = x[4] + f * (x_new[4] - x[4])
            if gamma_exit > 0.0:
                return _exit_pass(t + f * period, h + f * (h_new - h), x[3] + f * (x_new[3] - x[3]), gamma_exit,
                                  model, s)
        sign = lateral.bank_sign(sign, lateral.plane_error(x_new[2], x_new[5]), s.deadband)
        cmd = sign * (s1 if t + period < t_switch else sigma_2)
        sigma_new, rate = _actuator(sigma, rate, cmd, period, model)
        k, x, sigma_before, rho_before, sigma = k + 1, x_new, sigma, rho, sigma_new
        if h_new < s.h_floor:
            break
    return Pass(False, k * period, x[0] - r_earth, x[3], x[4], -math.inf, math.nan)


def exit_bank(x: float) -> float:
    """The exit arc's bank (rad) of the vertical lift fraction x = cos sigma_2 in [-1, 1]."""
    return min(math.acos(min(max(x, -1.0), 1.0)), LIFT_DOWN)


def solve_exit_bank(start, s1: float, t_switch: float, x_guess: float, model: TruthModel, s: OracleSettings):
    """(x, Pass, converged, predictions): x = cos sigma_2 putting the exit apogee within tolerance
    of the target, from the state `start` (`fly`) before the switch. The apogee grows with x;
    the miss in inverse apogee radius, 1/r_target - 1/r_apogee (finite for an unbound exit), is
    zeroed by secant steps from x_guess (at most 0.2 long; without two usable trials, steps of
    FIRST_STEP doubling up to 0.2) until two trials bracket it, then by regula falsi with the
    Illinois modification (`npc.bracket`); a pass that does not exit counts as too low (bisection
    when it is an end of the bracket). Not converged
    when x reaches a bound on the wrong side, when the bracket is narrower than JUMP (the apogee
    jumps over the target: a grazing exit arc climbs out or falls back, a reversal comes a step
    earlier or later) or after max_iter
    predictions: the nearest pass."""
    target = 1.0 / (model.r_earth + s.apogee_target)
    x, prev, low, high, side = min(max(x_guess, -1.0), 1.0), None, None, None, 0
    best, reach = None, FIRST_STEP
    for n in range(1, s.max_iter + 1):
        p = fly(start, s1, t_switch, exit_bank(x), model, s)
        miss = p.apogee - s.apogee_target
        if best is None or abs(miss) < abs(best[1].apogee - s.apogee_target):
            best = (x, p)
        if abs(miss) <= s.tolerance:
            return x, p, True, n
        f = target - 1.0 / (model.r_earth + p.apogee) if p.exited else -math.inf
        if (x <= -1.0 and f > 0.0) or (x >= 1.0 and f < 0.0):
            return best[0], best[1], False, n  # even the bound misses on the same side
        low, high, side = bracket(x, f, low, high, side)
        if low is not None and high is not None:
            if high[0] - low[0] <= JUMP:
                break  # the apogee jumps over the target here
            if math.isfinite(low[1]):
                candidate = low[0] - low[1] * (high[0] - low[0]) / (high[1] - low[1])
            else:
                candidate = 0.5 * (low[0] + high[0])
        elif math.isfinite(f) and prev is not None and prev[0] != x and (f - prev[1]) / (x - prev[0]) > 0.0:
            candidate = x + max(-0.2, min(0.2, -f * (x - prev[0]) / (f - prev[1])))
        else:  # no bracket yet, no usable secant: steps doubling from FIRST_STEP
            candidate = x - math.copysign(reach, f)
            reach = min(2.0 * reach, 0.2)
        prev = (x, f) if math.isfinite(f) else prev
        x = min(max(candidate, -1.0), 1.0)
    assert best is not None  # set by the first trial (max_iter >= 1)
    return best[0], best[1], False, n


class Trail:
    """The pass flown at the first arc's bank throughout, recorded at every communication point
    (`fly`): where each candidate switch starts flying."""

    def __init__(self, record):
        self.record = record

    def __len__(self):
        return len(self.record)

    def __getitem__(self, k: int):
        """The state from which a switch at the point k is flown: the point before it, over whose
        step the actuator follows the command of the point k (`fly`)."""
        return self.record[max(0, k - 1)]


class _Search:
    """The predictions of one run's search: the truth model, the entry and the count of
    predictions made."""

    def __init__(self, state, model: TruthModel, s: OracleSettings):
        self.model, self.s = model, s
        self.entry = entry_state(state, model)
        self.predictions = 0

    def trail(self) -> "Trail":
        """The pass flown at full lift up throughout, recorded at every communication point."""
        record: list = []
        fly(self.entry, 0.0, math.inf, 0.0, self.model, self.s, record)
        self.predictions += 1
        return Trail(record)

    def fly(self, start, t_switch, sigma_2) -> Pass:
        """`fly` after full lift up."""
        self.predictions += 1
        return fly(start, 0.0, t_switch, sigma_2, self.model, self.s)

    def exit_bank(self, start, t_switch, x_guess):
        """(dv, t_switch, x, Pass): `solve_exit_bank`, dv inf when the pass is not admissible (its
        apogee more than `accept` off the target, or ending after horizon - horizon_margin)."""
        x, p, _, n = solve_exit_bank(start, 0.0, t_switch, x_guess, self.model, self.s)
        self.predictions += n
        ok = abs(p.apogee - self.s.apogee_target) <= self.s.accept and p.t <= self.s.horizon - self.s.horizon_margin
        return (p.dv_total if ok else math.inf), t_switch, x, p


def _latest_switch(search: _Search):
    """(dv, t_switch, x, Pass) of the latest admissible switch point found after full lift up
    whose exit bank is at most sigma_2_max (the dv falls as the switch moves later, module
    docstring), or None. A switch point k admits such a bank when the pass flown with sigma_2_max
    from it ends below the target (or not at all): the latest such point by bisection, one
    prediction each. When its solved pass is not admissible (the apogee jumps over the target, or
    the pass ends too late), the switch steps earlier by `walk` points until one is, then
    bisection between the two on admissibility, a solve each; then the next two points after the
    one found, while one of them is admissible with a lower dv (a pass whose apogee jumps over the
    band at one point may not at the next). The admissible pass of lowest dv among those solved
    is returned (a later switch may land farther from the target: 0.3-0.5 m/s per km)."""
    s, period = search.s, search.s.command_period
    trail = search.trail()

    def low_enough(k):
        p = search.fly(trail[k], k * period, s.sigma_2_max)
        return not p.exited or p.apogee <= s.apogee_target

    lo, hi = 0, len(trail)
    if not low_enough(lo):
        return None
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (mid, hi) if low_enough(mid) else (lo, mid)
    solved: dict = {}  # switch point: the admissible exit bank found there (warm starts)
    tried: dict = {}  # switch point: every solve

    def solve_at(k, fallback):
        if k in tried:
            return tried[k]
        near = sorted(solved, key=lambda j: abs(j - k))[:2]
        if len(near) == 2:
            (j0, j1) = near
            guess = solved[j0] + (solved[j1] - solved[j0]) * (k - j0) / (j1 - j0)
        else:
            guess = solved[near[0]] if near else fallback
        trial = tried[k] = search.exit_bank(trail[k], k * period, guess)
        if math.isfinite(trial[0]):
            solved[k] = trial[2]
        return trial

    bad, good = lo, solve_at(lo, math.cos(s.sigma_2_max))
    for _ in range(s.steps_back):
        if math.isfinite(good[0]) or bad == 0:
            break
        bad = round(good[1] / period)
        good = solve_at(max(0, bad - s.walk), good[2])
    if not math.isfinite(good[0]):
        return None
    while bad - round(good[1] / period) > 1:
        k = (round(good[1] / period) + bad) // 2
        trial = solve_at(k, good[2])
        good, bad = (trial, bad) if math.isfinite(trial[0]) else (good, k)
    while True:  # admissibility is not monotone (a jump at one point): the next two points may do better
        k = round(good[1] / period)
        better = [t for t in (solve_at(j, good[2]) for j in (k + 1, k + 2) if j <= lo) if t[0] < good[0]]
        if not better:  # the lowest dv of every admissible pass solved (a later one may land farther off)
            return min((t for t in tried.values() if math.isfinite(t[0])), key=lambda t: t[0])
        good = min(better, key=lambda t: t[0])


def solve(state, model: TruthModel, s: OracleSettings) -> Plan:
    """The oracle's Plan from the measured entry state (h m, v m/s, gamma rad, phi rad, psi rad)
    (module docstring): the latest admissible switch after a lift-up first arc; without one, the
    constant bank (admissible or not)."""
    search = _Search(state, model, s)
    best = _latest_switch(search)
    if best is None:
        best = search.exit_bank(search.entry, 0.0, 0.0)
    dv, t_switch, x, p = best
    return Plan(t_switch, exit_bank(x), p, math.isfinite(dv), search.predictions)
