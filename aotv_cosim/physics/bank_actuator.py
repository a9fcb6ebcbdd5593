"""Bank-angle actuator with rate and acceleration limits, and a count of bank reversals.

The bank angle sigma (rad) follows its command as fast as the limits allow (time-optimal,
bang-bang in acceleration). Every substep h of at most `SUBSTEP` s, with e = command - sigma and
w the rate toward the command: w grows by accel_limit h (up to rate_limit) if it points away from
the command or if the stopping distance w^2 / (2 accel_limit) after the substep still fits in what
is left of |e|; it is held if that fits at the present rate; otherwise it brakes by accel_limit h.
sigma moves by the mean of the old and new rates times h (exact for a constant acceleration over
the substep); within accel_limit h^2 of the command and below accel_limit h of rate it settles on
the command at rest. The error e is taken the short way round, wrapped into (-pi, pi], and sigma
is kept in (-pi, pi]: a reversal from +sigma to -sigma passes through lift up (0) when
|sigma| < 90 deg and through lift down (pi) when |sigma| > 90 deg, the shorter of the two, so a
reversal does not fly the opposite vertical lift on the way.

Reference values (stated in the scenarios): 20 deg/s and 5 deg/s^2, the bank rate and acceleration
limits of the Mars Science Laboratory entry guidance (Mendeck & Craig, "Entry guidance for the 2011
Mars Science Laboratory mission", AIAA 2011-6639).
"""

import math

SUBSTEP = 0.05
"""Longest substep of the actuator's integration, s."""


def step(sigma: float, rate: float, command: float, dt: float, rate_limit: float,
         accel_limit: float):
    """(sigma rad, rate rad/s) after dt (s) toward `command` (rad), rate_limit in rad/s,
    accel_limit in rad/s^2 (both > 0), by substeps of at most SUBSTEP s (module docstring).

    Written for speed (every run of the aerocapture sets steps it 20 times a second): the
    constants of the substeps hoisted, `wrap` inlined, and the substeps left once the bank has
    settled on the command at rest, which every later substep would repeat; the same operations
    on the same values as the substep loop of the docstring, so the same numbers."""
    n = max(1, math.ceil(dt / SUBSTEP - 1e-9))
    h = dt / n
    fmod, pi, two_pi = math.fmod, math.pi, 2.0 * math.pi
    dv = accel_limit * h
    settle, two_accel = dv * h, 2.0 * accel_limit
    for _ in range(n):
        e = fmod(command - sigma + pi, two_pi)  # wrap(command - sigma)
        e = (e + two_pi if e <= 0.0 else e) - pi
        size = abs(e)
        if size <= settle and abs(rate) <= dv:
            sigma, rate = command, 0.0
            break  # settled: every later substep settles again
        direction = 1.0 if e > 0.0 else -1.0
        toward = rate * direction
        faster = toward + dv
        if not faster < rate_limit:  # min(rate_limit, toward + dv)
            faster = rate_limit
        if toward <= 0.0 or faster * faster <= two_accel * (size - 0.5 * (toward + faster) * h):
            toward = faster  # moving away, or can still stop on the command after this substep
        elif toward * toward > two_accel * (size - toward * h):
            toward -= dv
        new_rate = direction * toward
        sigma += 0.5 * (rate + new_rate) * h
        rate = new_rate
    return wrap(sigma), rate


def wrap(angle: float) -> float:
    """angle (rad) brought into (-pi, pi]."""
    a = math.fmod(angle + math.pi, 2.0 * math.pi)
    a = a + 2.0 * math.pi if a <= 0.0 else a
    return a - math.pi


def side(sigma: float) -> int:
    """+1 when the bank turns toward increasing heading (sin sigma > 0), -1 the other way, 0 on
    the vertical plane (sigma = 0 or pi)."""
    s = math.sin(sigma)
    return 1 if s > 1e-12 else -1 if s < -1e-12 else 0
