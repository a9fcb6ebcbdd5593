"""Predictive time-linear control of seed 000 (Ch. 6) and predictive adaptation to K (Sec. 8.1).

Given a (perturbed) entry state and the unchanged exit targets, find the law u = a + b t (4.8)
and the time in the atmosphere tf' such that the planar model (2.7), flown from the entry, meets
all three exit conditions at tf' (Ch. 6: six boundary conditions, three unknowns, free tf').

`solve_predictive` solves the three terminal residuals for (a, b, tf') at once by damped Newton,
with the exact Jacobian: the sensitivities d x(tf)/d(a, b) are integrated with the state (linear
variational equations with the matrices of eqs. 5.2/5.3) and d x(tf)/d tf' = f(x(tf'), u(tf')).
`solve_from_known` reaches an entry far from the fits' (the aerocapture sets) by continuation
from a known solution, the mission's nominal. `solve_predictive_thesis` is the thesis's own
iteration (6.1)-(6.4), kept as a faithful mode: an inner 2-unknown shooting for (a, b) at fixed
tf', then the tf' update (6.3) with the closed-form slope (6.4). It does not converge
(extraction Sec. 8 item 12) and reports its tf' history.

Everything here is SI (m, m/s, rad, m/s^2, s); the equations are unit-consistent. K (k_ball) is in
1/m, as in Table 8.1, except inside the fits (8.2)-(8.4), which need it in 1/km.
"""

import math
import time
from dataclasses import dataclass

import numpy as np

from aotv_cosim.guidance.time_linear import closed_form_gamma_rate
from aotv_cosim.physics.planar import (
    EXIT_000, K_BALL_000, AotvConstants, dynamics, time_linear_variational,
)

RTOL = 1e-10
"""Relative tolerance of the DOP853 integrations."""
_ATOL = np.array([1e-5, 1e-7, 1e-12, 1e-6, 1e-6, 1e-6, 1e-9, 1e-9, 1e-9])
"""Absolute tolerances of (r m, v m/s, gamma rad) and of the six sensitivities to (a, b)."""
TERMINAL_TOL = np.array([1e-2, 1e-5, 1e-8])
"""Convergence test on the exit residuals (h m, v m/s, gamma rad)."""


@dataclass(frozen=True)
class PredictiveSolution:
    """A time-linear law u = a + b t on [0, tf] (eq. 4.8) and how it was found.

    a in m/s^2, b in m/s^3, tf (tf') in s; residual: exit error (h m, v m/s, gamma rad) of the
    last trajectory flown; iterations: Newton iterations (integrations); solve_time in s.
    """

    a: float
    b: float
    tf: float
    residual: np.ndarray
    iterations: int
    converged: bool
    solve_time: float


def _entry_state(entry, c: AotvConstants) -> np.ndarray:
    """(h m, v m/s, gamma rad) -> (r m, v m/s, gamma rad)."""
    return np.array([c.r_earth + entry[0], entry[1], entry[2]])


def _ground(_t, y, _a, _b, c: AotvConstants) -> float:
    """Altitude r - R_e (m): its zero, crossed downward, is the trajectory hitting the ground."""
    return y[0] - c.r_earth


_ground.terminal = True  # type: ignore[attr-defined]  # read by solve_ivp
_ground.direction = -1  # type: ignore[attr-defined]  # read by solve_ivp


class _EnergyFloor:
    """Event of a flight that can no longer reach the exit: its specific energy v^2/2 + g r (m^2/s^2),
    which drag only lowers (d/dt = -K exp(-h/H) v^3 in (2.7)) and lift does not change, falls below
    that of the exit point flown at half the exit speed, so its exit speed would miss by more than
    half the target. Such a flight ends in dense air at a few m/s, where (2.7) is stiff: a Newton
    trial of a steep aerocapture entry integrated for minutes before this event stopped it."""

    terminal = True
    direction = -1

    def __init__(self, exit_target, c: AotvConstants):
        self.floor = 0.125 * exit_target[1] ** 2 + c.g * (c.r_earth + exit_target[0])

    def __call__(self, _t, y, _a, _b, c: AotvConstants) -> float:
        return 0.5 * y[1] * y[1] + c.g * y[0] - self.floor


def _loop(_t, y, _a, _b, _c) -> float:
    """pi/2 - |gamma|: its zero, crossed downward, is a flight turning past the vertical (a Newton
    trial with a lift of hundreds of m/s^2 loops over and over above the atmosphere, where no
    event of the energy or the ground stops it; no aerocapture pass flies there)."""
    return 0.5 * math.pi - abs(y[2])


_loop.terminal = True  # type: ignore[attr-defined]  # read by solve_ivp
_loop.direction = -1  # type: ignore[attr-defined]  # read by solve_ivp


def _terminal_with_sensitivities(x0, a: float, b: float, tf: float, c: AotvConstants, events=()):
    """State x(tf) (r m, v m/s, gamma rad) of (2.7) under u = a + b t and the 3x3 Jacobian of
    x(tf) with respect to (a, b, tf); None if one of the terminal events (`_ground`,
    `_EnergyFloor`, `_loop`) stops the flight before tf.

    The sensitivities S = dx/d(a, b) obey dS/dt = A S + B (1, t) with A, B of eqs. (5.2)/(5.3)
    along the trajectory (`planar.time_linear_variational`); (5.2) drops cos(gamma) in A(3,1), so the Jacobian is
    approximate to a relative 3e-4 in that entry, which slows Newton negligibly and does not move the root.
    Events do not change the steps taken (solve_ivp locates them after each step).
    """
    from scipy.integrate import solve_ivp  # here: not every law needs scipy

    y0 = np.concatenate([x0, np.zeros(6)])
    sol = solve_ivp(time_linear_variational, (0.0, tf), y0, method="DOP853", rtol=RTOL, atol=_ATOL,
                    args=(a, b, c), events=list(events) or None)
    if sol.status == 1:
        return None
    y = sol.y[:, -1]
    x = y[:3]
    jac = np.column_stack([y[3:].reshape(3, 2), dynamics(x, a + b * tf, c)])
    return x, jac


_NOT_FLOWN = object()
"""Marks a Newton trial that was not integrated (tf' <= 0) or overflowed."""


def _flown_trial(x0, trial, c: AotvConstants, floor: _EnergyFloor, last: bool):
    """x(tf) and the Jacobian for the trial (a, b, tf'); None if it hits the ground (all but the
    last halving stop there), its energy falls below the floor or it loops; _NOT_FLOWN if tf' <= 0. The
    last halving is flown through the ground, as it always was; a float overflow there
    (exp(-h/H) far below the ground) counts as not flown."""
    a, b, tf = trial
    if tf <= 0.0:
        return _NOT_FLOWN
    if not last:
        return _terminal_with_sensitivities(x0, a, b, tf, c, (_ground, floor, _loop))
    try:
        return _terminal_with_sensitivities(x0, a, b, tf, c, (floor, _loop))
    except (OverflowError, FloatingPointError):
        return _NOT_FLOWN


def _bounded(step, tf: float, max_du: float, max_dtf: float) -> np.ndarray:
    """The Newton step (da m/s^2, db m/s^3, dtf s) scaled down, direction kept, so that the command
    changes by at most max_du (m/s^2) on [0, tf] (|da| + |db| tf) and tf' by at most max_dtf tf."""
    scale = max((abs(step[0]) + abs(step[1]) * tf) / max_du, abs(step[2]) / (max_dtf * tf), 1.0)
    return step / scale


def _residual(x, exit_target, c: AotvConstants) -> np.ndarray:
    """Exit error (h m, v m/s, gamma rad) of the state x = (r, v, gamma)."""
    return np.array([x[0] - c.r_earth - exit_target[0], x[1] - exit_target[1],
                     x[2] - exit_target[2]])


def solve_predictive(entry, exit_target=EXIT_000, k_ball: float = K_BALL_000,
                     guess: tuple[float, float, float] | None = None,
                     max_iter: int = 20, max_step: tuple[float, float] | None = None
                     ) -> PredictiveSolution:
    """Solve for (a, b, tf') of the predictive time-linear law (Ch. 6, eqs. 4.8, 6.1, 6.2).

    entry: (h0 m, v0 m/s, gamma0 rad); exit_target: (hf m, vf m/s, gammaf rad); k_ball: K in 1/m.
    guess: (a m/s^2, b m/s^3, tf s); None starts from the K fit (8.2)-(8.4) with the corrected
    intercept. Damped Newton on the three exit residuals: the step is halved until the scaled
    residual norm decreases (scales 1 km, 1 m/s, 1 mrad; at most 7 halvings, the last one taken
    whatever its residual). A trial whose trajectory hits the ground counts as not decreasing it
    and is not flown to tf: a full Newton step from the K fit's guess can end 22 km below the
    ground at 1 m/s, where the flight-path equation is stiff and DOP853 took 130,000 evaluations
    (4 s; 2 runs in 40 of the benchmark campaign). Such a trajectory is ~8 km/s short of the exit
    speed, so its residual never decreased the norm and the iterates are unchanged.

    Guards stop a solve that cannot progress instead of flying nonsense (they were added for the
    aerocapture entries; the seed-000 scenarios and both seed-000 predictive benchmark campaigns,
    N = 1000, give the same rows with and without them): a flight whose energy falls below
    `_EnergyFloor`, or that turns past the vertical (`_loop`), stops there (the first one ends the
    solve, unconverged); a trial with tf' <= 0 is not flown (a Newton step from a trajectory that
    falls vertically asked for tf' = -1.7e8 s and integrated backwards for minutes); a last
    halving that cannot be flown (tf' <= 0, an event, a float overflow deep below the ground) or a
    singular Jacobian ends the solve, unconverged, at z.
    max_step: (m/s^2, fraction) bounds of each Newton step (`_bounded`), None for the full step.
    """
    start = time.perf_counter()
    c = AotvConstants.si(k_ball)
    x0 = _entry_state(entry, c)
    z = np.array(guess if guess is not None else table_8_1_fit(k_ball, corrected_intercept=True))
    weights = np.array([1e-3, 1.0, 1e3])
    floor = _EnergyFloor(exit_target, c)
    first = _terminal_with_sensitivities(x0, z[0], z[1], z[2], c, (floor, _loop)) if z[2] > 0.0 else None
    if first is None:
        return PredictiveSolution(float(z[0]), float(z[1]), float(z[2]), np.full(3, np.inf), int(z[2] > 0.0),
                                  False, time.perf_counter() - start)
    res = _residual(first[0], exit_target, c)
    jac = first[1]
    iterations = 1
    while not np.all(np.abs(res) < TERMINAL_TOL) and iterations < max_iter:
        try:
            step = np.linalg.solve(jac, -res)
        except np.linalg.LinAlgError:  # a singular Jacobian: no Newton direction from z
            break
        if max_step is not None:
            step = _bounded(step, z[2], *max_step)
        norm = np.linalg.norm(weights * res)
        for halving in range(8):
            trial = z + step / 2.0 ** halving
            flown = _flown_trial(x0, trial, c, floor, last=halving == 7)
            iterations += flown is not _NOT_FLOWN
            if flown is None or flown is _NOT_FLOWN:
                continue
            trial_res = _residual(flown[0], exit_target, c)
            if halving == 7 or np.linalg.norm(weights * trial_res) < norm:
                break
        else:  # not even the last halving could be flown: no step is possible from z
            break
        z, jac, res = trial, flown[1], trial_res
    converged = bool(np.all(np.abs(res) < TERMINAL_TOL))
    return PredictiveSolution(float(z[0]), float(z[1]), float(z[2]), res, iterations, converged,
                              time.perf_counter() - start)


CONTINUATION_STEP = (1.0, 0.25)
"""Largest Newton step of a continuation solve: 1 m/s^2 of command anywhere on [0, tf'] and a
quarter of tf'. Each solve starts from the solution of a nearby problem, so a larger step means a
Jacobian taken far from the root (a steep entry's first flight falls vertically), not progress."""


@dataclass(frozen=True)
class KnownSolution:
    """A start for `solve_from_known`: (a m/s^2, b m/s^3, tf' s) near the solution of the problem
    with entry (h m, v m/s, gamma rad) and K k_ball (1/m), e.g. the mission's nominal."""

    entry: tuple[float, float, float]
    k_ball: float
    guess: tuple[float, float, float]


def solve_from_known(entry, exit_target, k_ball: float, known: KnownSolution,
                     max_flights: int = 200, min_fraction: float = 1.0 / 64.0) -> PredictiveSolution:
    """`solve_predictive` for (entry, k_ball), by continuation from a known problem's solution.

    The known problem is solved first from its guess; then the entry state and K move from the
    known problem's towards (entry, k_ball) in fractions lambda of the way, each solve starting
    from the last converged (a, b, tf'): a full step is tried first, a failed one is halved (down
    to min_fraction), a converged one lets the next step double. This is how the law flies an
    entry far from the one its Table 8.1 fits describe: a steep entry of the AFE-class aerocapture
    set, started directly from the nominal's (a, b, tf'), first flies a trajectory that falls
    vertically, and no Newton step from there is usable. Stops unconverged after max_flights
    integrations in all; iterations counts them all.
    """
    start = time.perf_counter()
    known_entry = np.asarray(known.entry, dtype=float)
    entry = np.asarray(entry, dtype=float)
    sol = solve_predictive(known_entry, exit_target, known.k_ball, known.guess)
    flights = sol.iterations
    done, fraction = 0.0, 1.0
    while sol.converged and done < 1.0 and flights < max_flights:
        lam = min(1.0, done + fraction)
        trial = solve_predictive(known_entry + lam * (entry - known_entry), exit_target,
                                 known.k_ball + lam * (k_ball - known.k_ball), (sol.a, sol.b, sol.tf),
                                 max_step=CONTINUATION_STEP)
        flights += trial.iterations
        if trial.converged:
            sol, done, fraction = trial, lam, 2.0 * fraction
        elif fraction / 2.0 < min_fraction:
            sol = trial
        else:
            fraction /= 2.0
    converged = sol.converged and done == 1.0
    return PredictiveSolution(sol.a, sol.b, sol.tf, sol.residual, flights, converged,
                              time.perf_counter() - start)


def _solve_ab_fixed_tf(x0, exit_target, a: float, b: float, tf: float, c: AotvConstants,
                       max_iter: int):
    """Inner problem of Fig. 6.1: (a, b) meeting r(tf) = rf, v(tf) = vf at fixed tf, eq. (6.2).

    Newton on the two residuals; returns (a, b, final state x(tf))."""
    for _ in range(max_iter):
        x, jac = _terminal_with_sensitivities(x0, a, b, tf, c)
        res = _residual(x, exit_target, c)
        if np.all(np.abs(res[:2]) < TERMINAL_TOL[:2]):
            break
        da, db = np.linalg.solve(jac[:2, :2], -res[:2])
        a, b = a + da, b + db
    return a, b, x


def solve_predictive_thesis(entry, exit_target=EXIT_000, k_ball: float = K_BALL_000,
                            guess: tuple[float, float, float] = (0.77, -2.57e-3, 300.0),
                            n_updates: int = 12, inner_iter: int = 10):
    """The thesis's iteration of Fig. 6.1, eqs. (6.1)-(6.4), run for n_updates tf' updates.

    entry, exit_target in SI as in `solve_predictive`; guess: starting (a m/s^2, b m/s^3, tf' s).
    Each pass solves (a, b) at fixed tf' (6.1)/(6.2), then applies (6.3) with the printed '+'
    sign, tf' <- tf' + (gamma(tf') - gammaf) / (d gamma/d tf'), the slope being (6.4), the time
    derivative of the closed form (4.22) at fixed (a, b). Returns the list of
    (a, b, tf', gamma(tf') - gammaf) after each pass, in SI.
    """
    c = AotvConstants.si(k_ball)
    x0 = _entry_state(entry, c)
    a, b, tf = guess
    history = []
    for _ in range(n_updates):
        a, b, x = _solve_ab_fixed_tf(x0, exit_target, a, b, tf, c, inner_iter)
        miss = x[2] - exit_target[2]
        history.append((float(a), float(b), float(tf), float(miss)))
        tf = tf + miss / closed_form_gamma_rate(tf, entry, a, b)
    return history


def fly_time_linear(entry, a: float, b: float, tf: float, k_ball: float = K_BALL_000,
                    t_eval=None):
    """Fly (2.7) from entry (h0 m, v0 m/s, gamma0 rad) under u = a + b t on [0, tf] (DOP853).

    Returns (t s, h m, v m/s, gamma rad) at t_eval (default: the solver's steps)."""
    from scipy.integrate import solve_ivp

    c = AotvConstants.si(k_ball)
    sol = solve_ivp(lambda t, x: dynamics(x, a + b * t, c), (0.0, tf), _entry_state(entry, c),
                    method="DOP853", rtol=RTOL, atol=_ATOL[:3], t_eval=t_eval)
    return sol.t, sol.y[0] - c.r_earth, sol.y[1], sol.y[2]


def estimate_k_ball(v_dot: float, h0: float, v0: float, gamma0: float,
                    g: float = AotvConstants.si().g,
                    scale_height: float = AotvConstants.si().scale_height) -> float:
    """Ballistic parameter from the measured deceleration at entry, eq. (8.1), in 1/m.

    K = -(v_dot + g sin gamma0) / (exp(-h0/H) v0^2), with v_dot the measured dv/dt (m/s^2, the
    specific force along v, negative when decelerating), h0 in m, v0 in m/s, gamma0 in rad, g in
    m/s^2, H in m. As in (2.7), K absorbs the base density rho_s.
    """
    return -(v_dot + g * math.sin(gamma0)) / (math.exp(-h0 / scale_height) * v0 * v0)


def solve_predictive_adaptive(entry, drag_acc: float, exit_target=EXIT_000,
                              g: float = AotvConstants.si().g,
                              scale_height: float = AotvConstants.si().scale_height,
                              known: KnownSolution | None = None):
    """Predictive adaptive law of Sec. 8.1: K from the entry deceleration (8.1), then (a, b, tf').

    entry: (h0 m, v0 m/s, gamma0 rad); drag_acc: the drag specific force D/m measured at entry
    (m/s^2, positive), so the measured dv/dt of (2.7) is -drag_acc - g sin(gamma0). (a, b, tf')
    are re-solved by `solve_predictive` for the estimated K (rather than read off the fits
    (8.2)-(8.4)), or continued from `known` when given (`solve_from_known`). Returns (K in 1/m,
    PredictiveSolution) with solve_time covering both steps.
    """
    start = time.perf_counter()
    v_dot = -drag_acc - g * math.sin(entry[2])
    k_est = estimate_k_ball(v_dot, entry[0], entry[1], entry[2], g, scale_height)
    if known is None:
        sol = solve_predictive(entry, exit_target, k_est)
    else:
        sol = solve_from_known(entry, exit_target, k_est, known)
    return k_est, PredictiveSolution(sol.a, sol.b, sol.tf, sol.residual, sol.iterations,
                                     sol.converged, time.perf_counter() - start)


TF_INTERCEPT_PRINTED = 448.94712
"""Intercept of eq. (8.4) as printed, s."""
TF_INTERCEPT_CORRECTED = 449.94712
"""Intercept of the line through the first and last rows of Table 8.1, s: the printed value is
1.000 s low at both end points (extraction Sec. 8 item 3)."""


def table_8_1_fit(k_ball: float, corrected_intercept: bool = False) -> tuple[float, float, float]:
    """Linear fits (8.2)-(8.4) of Table 8.1: (a m/s^2, b m/s^3, tf s) for the nominal entry.

    k_ball in 1/m (as Table 8.1 lists it); the fits are evaluated with K in 1/km, the only reading
    that reproduces the table (extraction Sec. 8 item 2). corrected_intercept replaces the printed
    448.94712 s of (8.4) by 449.94712 s.
    """
    k_km = k_ball * 1e3
    intercept = TF_INTERCEPT_CORRECTED if corrected_intercept else TF_INTERCEPT_PRINTED
    return (2.32306 * k_km + 0.090752,
            (-8.99571 * k_km + 0.0623299) * 1e-3,
            -503.94971 * k_km + intercept)
