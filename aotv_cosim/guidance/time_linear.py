"""Approximate time-linear optimal lift law of seed 000 (Sec. 4.4, eqs. 4.23 and 4.28).

The thesis works in km, s and rad (extraction Sec. 2.2 and Sec. 8 item 1): lambda_r(tf) is in
km/s^3, and the entry state enters (4.28) with v0 in km/s, gamma0 in rad and h0 in km. These
functions take and return SI values and convert at the edge.

It also holds the approximate closed-form state under a time-linear law, eqs. (4.20)-(4.22), and
its flight-path-angle rate (6.4), which are unit-consistent and evaluated in SI.
"""

import math

import numpy as np

from aotv_cosim.physics.planar import K_BALL_000, AotvConstants


def lambda_r_empirical(v0: float, gamma0: float, h0: float, tf: float) -> float:
    """Empirical costate lambda_r(tf) of eq. (4.28), in km/s^3 (R = 1).

    v0 in m/s, gamma0 in rad, h0 in m, tf in s. At the reference point (8200 m/s, -0.02 rad,
    90 km, 300 s) it is -5.154396e-6 km/s^3 (extraction Sec. 4.3).
    """
    v_km = v0 / 1000.0
    h_km = h0 / 1000.0
    return (-1.828523e-4 + 2.3363e-5 * v_km + 5.340875e-4 * gamma0
            + 4.192336e-2 / h_km ** 2 - 1.910441e2 / h_km ** 4
            - 1.3614626e-4 * math.exp(-0.01072041435 * tf))


def approximate_law_coefficients(v0: float, gamma0: float, h0: float, tf: float,
                                 weight: float = 1.0):
    """Coefficients (a, b) of u(t) = a + b t, eq. (4.23): u = -lambda_r(tf) (tf - t) / (2R).

    Returns a in m/s^2 and b in m/s^3 (the km/s^3 costate of eq. 4.28 times 1000). The
    reference point gives a = 0.77316 m/s^2, b = -2.5772e-3 m/s^3 (extraction Sec. 4.3).
    """
    slope = lambda_r_empirical(v0, gamma0, h0, tf) / (2.0 * weight) * 1000.0
    return -slope * tf, slope


def _closed_form_terms(entry, a: float, c: AotvConstants):
    """r0 (m) and A = g (c_loh - 1) + a (m/s^2), with Loh's term c_loh = v0^2/(r0 g), eq. (4.10c)."""
    h0, v0, _gamma0 = entry
    r0 = c.r_earth + h0
    return r0, c.g * (v0 * v0 / (r0 * c.g) - 1.0) + a


def closed_form_state(t, entry, a: float, b: float, tf: float, k_ball: float = K_BALL_000):
    """Approximate state (h m, v m/s, gamma rad) at t (s) under u = a + b t, eqs. (4.20)-(4.22).

    entry: (h0 m, v0 m/s, gamma0 rad); a in m/s^2, b in m/s^3; tf (s) sets the averaging window
    of r_avg = r0 + v0 gamma0 tf/2 + A tf^2/6 + b tf^3/24 (time mean of 4.20), which freezes the
    drag in p = K exp(-(r_avg - R_e)/H) (assumption 4 of Sec. 4.3); k_ball: K in 1/m. Table 4.1
    constants otherwise; t may be an array.
    """
    c = AotvConstants.si(k_ball)
    _h0, v0, gamma0 = entry
    r0, big_a = _closed_form_terms(entry, a, c)
    t = np.asarray(t, dtype=float)
    r_avg = r0 + v0 * gamma0 * tf / 2.0 + big_a * tf ** 2 / 6.0 + b * tf ** 3 / 24.0
    p = c.k_ball * math.exp(-(r_avg - c.r_earth) / c.scale_height)
    k = p * v0
    decay = np.exp(-k * t)
    gain = c.g / k
    r = r0 + v0 * gamma0 * t + big_a * t ** 2 / 2.0 + b * t ** 3 / 6.0
    v = (v0 * decay
         + gain * (-gamma0 + big_a / (p * v0 ** 2) - b / (p ** 2 * v0 ** 3)) * (1.0 - decay)
         - gain * (big_a / v0 - b / (p * v0 ** 2)) * t
         - gain * (b / (2.0 * v0)) * t ** 2)
    gamma = gamma0 + big_a * t / v0 + b * t ** 2 / (2.0 * v0)
    return r - c.r_earth, v, gamma


def closed_form_gamma_rate(t: float, entry, a: float, b: float) -> float:
    """d gamma/dt of the closed form (4.22) at t (s), eq. (6.4), in rad/s.

    entry: (h0 m, v0 m/s, gamma0 rad); a in m/s^2, b in m/s^3 (a and b held fixed).
    """
    _h0, v0, _gamma0 = entry
    _r0, big_a = _closed_form_terms(entry, a, AotvConstants.si())
    return big_a / v0 + b * t / v0


def time_linear_integrals(a: float, b: float, tf: float):
    """(int_0^tf |u| dt in m/s, int_0^tf u^2 dt in m^2/s^3) of u = a + b t, eq. (4.8), exactly.

    a in m/s^2, b in m/s^3, tf in s. The first is the "int |u| dt" column of Table 8.1 (there in
    km/s), the second the cost J of eq. (3.2) with R = 1.
    """
    def primitive(t):
        return a * t + 0.5 * b * t * t

    total = abs(primitive(tf))
    if b != 0.0 and 0.0 < -a / b < tf:
        crossing = -a / b
        total = abs(primitive(crossing)) + abs(primitive(tf) - primitive(crossing))
    return total, a * a * tf + a * b * tf ** 2 + b * b * tf ** 3 / 3.0
