"""One actuator channel: position saturation of the command, then first-order lag, then rate limit."""

import math


def saturate(x: float, lower: float, upper: float) -> float:
    """Clip x to [lower, upper]."""
    return lower if x < lower else upper if x > upper else x


def advance(position: float, command: float, dt: float, time_constant: float,
            rate_limit: float) -> float:
    """Actuator position after dt (s) with the command held (zero-order hold).

    A positive time_constant (s) makes the position follow the command as a first-order lag,
    solved exactly over dt; a finite positive rate_limit (unit/s) bounds the change to
    rate_limit * dt. With both disabled (time_constant <= 0, rate_limit = inf) the position
    equals the command.
    """
    target = command
    if time_constant > 0.0:
        target = command + (position - command) * math.exp(-dt / time_constant)
    if math.isfinite(rate_limit):
        step = rate_limit * dt
        target = saturate(target, position - step, position + step)
    return target
