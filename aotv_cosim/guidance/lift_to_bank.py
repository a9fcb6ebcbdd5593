"""A lift-acceleration command flown by bank angle: cos sigma = u / u_available.

A vehicle at trim has one lift vector, L/m = q C_L S / m, and steers its vertical part by the bank
angle: u = (L/m) cos sigma. A law that commands the vertical lift acceleration u directly (the
seed-000 laws, eq. 2.9) is flown by sigma = sign arccos(u / u_available), u/u_available clipped to
[-1, 1]: the command saturates (full lift up, sigma = 0, or full lift down, sigma = pi) when it
asks for more lift than the air gives at this density and speed.
"""

import math


def bank_for_lift(u: float, u_available: float, sign: int = 1):
    """(sigma rad, saturated bool) that flies the vertical lift acceleration u (m/s^2) with the
    available lift u_available (m/s^2, >= 0); sign (+1/-1) is the side of the bank (lateral
    logic). With no lift available (u_available <= 0) the bank holds lift up or down by the sign
    of u, saturated unless u is 0."""
    if u_available <= 0.0:
        return (0.0 if u >= 0.0 else sign * math.pi), u != 0.0
    ratio = u / u_available
    saturated = abs(ratio) > 1.0
    ratio = max(-1.0, min(1.0, ratio))
    return sign * math.acos(ratio), saturated
