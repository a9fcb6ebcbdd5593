"""Impulses that take the post-exit orbit of an aeroassisted pass into a circular target orbit.

The seed-000 thesis stops at exit and circularises at apogee (Ch. 9; extraction Sec. 7); when the
apogee misses the target the standard aerocapture cost (Lu et al., "Optimal aerocapture
guidance", JGCD 38(4), 2015: first burn at apoapsis to raise the periapsis, second burn
to correct the apoapsis) is a two-impulse correction. For a circular target of radius r_t and an
exit orbit of apsis radii (r_p, r_a), with the vis-viva speed v(r; r1, r2)^2 = mu (2/r - 2/(r1 + r2)):
    dv1 = |v(r_a; r_a, r_t) - v(r_a; r_p, r_a)|   at the apogee r_a: other apsis moved to r_t,
    dv2 = |sqrt(mu/r_t) - v(r_t; r_a, r_t)|        at r_t: circularise.
When r_a = r_t, dv1 is the circularisation impulse of `orbit.circularization_delta_v` and dv2 = 0.
SI units: radii in m, mu in m^3/s^2, speeds in m/s.
"""

import math


def vis_viva_speed(r: float, r1: float, r2: float, mu: float) -> float:
    """Speed (m/s) at radius r (m) on the ellipse of apsis radii r1, r2 (m)."""
    return math.sqrt(mu * (2.0 / r - 2.0 / (r1 + r2)))


def circularization_corrections(r_p: float, r_a: float, r_t: float, mu: float):
    """(dv1, dv2) in m/s of the two-impulse correction from the orbit (r_p, r_a) to the circular
    orbit of radius r_t (module docstring); radii in m, mu in m^3/s^2."""
    dv1 = abs(vis_viva_speed(r_a, r_a, r_t, mu) - vis_viva_speed(r_a, r_p, r_a, mu))
    dv2 = abs(math.sqrt(mu / r_t) - vis_viva_speed(r_t, r_a, r_t, mu))
    return dv1, dv2
