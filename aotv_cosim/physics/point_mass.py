"""3-D point-mass equations of motion over a spherical, non-rotating Earth (Vinh's form).

State x = (r, theta, phi, v, gamma, psi): radius (m), longitude (rad), latitude (rad), speed (m/s),
flight-path angle (rad, positive up) and heading (rad, measured from east toward north, so psi = 0
is due east). These are seed 002 eqs. (1)-(6) and seed 001 eqs. (3.1)-(3.6); with bank sigma = 0,
psi = phi = 0 and constant gravity they reduce to the planar seed-000 model, eq. (2.7), whose
theta is the downrange angle (seed 000 eq. 2.2).

Aerodynamic specific forces are written as
    L/m = lift_acc + (1/2) rho v^2 cl_s_m,        D/m = (1/2) rho v^2 cd_s_m,
so one function serves every seed: seed 000 commands the lift acceleration u = L/m directly
(lift_acc = u, cl_s_m = 0, cd_s_m = C_D0 / (m/S), eq. 2.6-2.9); seeds 001 and 002 give the lift
and drag coefficients (cl_s_m = C_L S / m, cd_s_m = C_D S / m). Within one integration step the
inputs (rho, lift_acc, cl_s_m, cd_s_m, sigma) are held constant: a zero-order hold, as the FMU
sees them.
"""

import math

GRAVITY_CONSTANT = 0
"""Gravity model code: constant g0 (seed 000, Sec. 2.1 assumption 3)."""
GRAVITY_INVERSE_SQUARE = 1
"""Gravity model code: g = mu / r^2 (seeds 001, 002)."""
HEADING_FULL = 0
"""Heading model code: the full 3-D heading equation (seed 002 eq. 6, seed 001 eq. 3.6)."""
HEADING_REDUCED = 1
"""Heading model code: seed 001's reduced heading equation, (3.6) without the
-V^2 cos(gamma) cos(psi) tan(phi)/r term, i.e. the time form of eq. (3.23) (Calise & Melamed
Sec. 3.1: theta and phi ignorable, psi approximates the inclination; extraction 2.5, 2.7)."""


def gravity(r: float, model: int, g0: float, mu: float) -> float:
    """Gravitational acceleration in m/s^2 at radius r (m): g0, or mu / r^2 (mu in m^3/s^2)."""
    if model == GRAVITY_CONSTANT:
        return g0
    return mu / (r * r)


def derivatives(x, rho, lift_acc, cl_s_m, cd_s_m, sigma, gravity_model, g0, mu,
                heading_model=HEADING_FULL):
    """Time derivative of x = (r, theta, phi, v, gamma, psi), SI units.

    rho: density (kg/m^3); lift_acc: commanded lift acceleration (m/s^2); cl_s_m, cd_s_m: C_L S/m
    and C_D S/m (m^2/kg); sigma: bank angle (rad, positive turns toward increasing psi).
    Seed 002 eqs. (1)-(6); seed 000 eq. (2.7) in the planar case. heading_model HEADING_REDUCED
    drops the tan(phi) term of the heading rate (seed 001 eq. 3.23); theta and phi are still
    integrated.
    """
    return _rates(x, rho, lift_acc, cl_s_m, cd_s_m, math.cos(sigma), math.sin(sigma),
                  gravity_model, g0, mu, heading_model)


def _rates(x, rho, lift_acc, cl_s_m, cd_s_m, cos_sigma, sin_sigma, gravity_model, g0, mu,
           heading_model=HEADING_FULL):
    """`derivatives` with the bank angle given by its cosine and sine (constant over an RK4 step).

    In the plane phi = psi = 0 with sigma = 0 the terms in cos(psi), sin(psi), cos(phi) and
    tan(phi) are 1 or 0 exactly, so they are left out: the same floating-point results, fewer
    operations (the vehicle FMU's inner loop)."""
    r, _theta, phi, v, gamma, psi = x
    q_over_m = 0.5 * rho * v * v
    lift = lift_acc + q_over_m * cl_s_m
    drag = q_over_m * cd_s_m
    g = g0 if gravity_model == GRAVITY_CONSTANT else mu / (r * r)  # `gravity`, inlined
    cg, sg = math.cos(gamma), math.sin(gamma)
    v_over_r = v / r
    if phi == 0.0 and psi == 0.0 and sin_sigma == 0.0 and cos_sigma == 1.0:
        return (v * sg, v * cg / r, 0.0, -drag - g * sg, (lift - (g - v * v_over_r) * cg) / v, 0.0)
    cp, sp = math.cos(psi), math.sin(psi)
    coupling = 0.0 if heading_model == HEADING_REDUCED else v * v_over_r * cg * cp * math.tan(phi)
    return (
        v * sg,
        v * cg * cp / (r * math.cos(phi)),
        v * cg * sp / r,
        -drag - g * sg,
        (lift * cos_sigma - (g - v * v_over_r) * cg) / v,
        (lift * sin_sigma / cg - coupling) / v,
    )


def rk4_step(x, dt, args):
    """One classical Runge-Kutta step of `derivatives` over dt (s) with inputs `args` held.

    x_n+1 = x + dt/6 (k1 + 2 k2 + 2 k3 + k4), stages at x + dt/2 k1, x + dt/2 k2, x + dt k3;
    written out per state variable (the vehicle FMU's inner loop; loops over six-element lists
    cost more here than the arithmetic), with the bank angle's cosine and sine taken once.
    """
    rho, lift_acc, cl_s_m, cd_s_m, sigma, *rest = args
    if x[2] == 0.0 and x[5] == 0.0 and sigma == 0.0:
        return _rk4_planar(x, dt, rho, lift_acc, cl_s_m, cd_s_m, *rest[:3])
    return _rk4_general(x, dt, rho, lift_acc, cl_s_m, cd_s_m, sigma, *rest)


def _rk4_general(x, dt, rho, lift_acc, cl_s_m, cd_s_m, sigma, gravity_model, g0, mu,
                 heading_model=HEADING_FULL):
    """`rk4_step` with `_rates` evaluated inside the stage loop instead of called: the same
    operations in the same order, its planar branch included for a stage that lands on phi = psi
    = 0 at sigma = 0, so the same results to the bit (tests/fmus/test_rk4_general.py); a third
    less time per step of the bank-steered vehicles, which never fly the planar case."""
    cos, sin = math.cos, math.sin
    cos_sigma, sin_sigma = cos(sigma), sin(sigma)
    level = sin_sigma == 0.0 and cos_sigma == 1.0
    reduced = heading_model == HEADING_REDUCED
    constant_g = gravity_model == GRAVITY_CONSTANT
    half_rho = 0.5 * rho  # 0.5 * rho * v * v evaluates (0.5 * rho) first
    x0, x1, x2, x3, x4, x5 = x
    r, phi, v, gamma, psi = x0, x2, x3, x4, x5
    stages = []
    for f in (0.5 * dt, 0.5 * dt, dt, None):  # each stage's rates, then the next stage's state
        q = half_rho * v * v
        lift = lift_acc + q * cl_s_m
        drag = q * cd_s_m
        g = g0 if constant_g else mu / (r * r)
        cg, sg = cos(gamma), sin(gamma)
        v_over_r = v / r
        if level and phi == 0.0 and psi == 0.0:
            k = (v * sg, v * cg / r, 0.0, -drag - g * sg, (lift - (g - v * v_over_r) * cg) / v, 0.0)
        else:
            cp, sp = cos(psi), sin(psi)
            coupling = 0.0 if reduced else v * v_over_r * cg * cp * math.tan(phi)
            k = (v * sg, v * cg * cp / (r * cos(phi)), v * cg * sp / r, -drag - g * sg,
                 (lift * cos_sigma - (g - v * v_over_r) * cg) / v, (lift * sin_sigma / cg - coupling) / v)
        stages.append(k)
        if f is not None:
            r, phi, v, gamma, psi = x0 + f * k[0], x2 + f * k[2], x3 + f * k[3], x4 + f * k[4], x5 + f * k[5]
    (a0, a1, a2, a3, a4, a5), (b0, b1, b2, b3, b4, b5), (c0, c1, c2, c3, c4, c5), (d0, d1, d2, d3, d4, d5) = stages
    s = dt / 6.0
    return [x0 + s * (a0 + 2.0 * b0 + 2.0 * c0 + d0), x1 + s * (a1 + 2.0 * b1 + 2.0 * c1 + d1),
            x2 + s * (a2 + 2.0 * b2 + 2.0 * c2 + d2), x3 + s * (a3 + 2.0 * b3 + 2.0 * c3 + d3),
            x4 + s * (a4 + 2.0 * b4 + 2.0 * c4 + d4), x5 + s * (a5 + 2.0 * b5 + 2.0 * c5 + d5)]


def _rk4_planar(x, dt, rho, lift_acc, cl_s_m, cd_s_m, gravity_model, g0, mu):
    """`rk4_step` in the plane phi = psi = sigma = 0, which it never leaves (their rates are 0):
    r, theta, v, gamma by the same operations as `_rates`' planar branch, so the same results to
    the bit, without the two idle states. The four stages are written out (no call, no tuple per
    stage: the vehicle FMU's innermost loop); each computes, at (r, v, gamma),
        q = rho v^2 / 2,  g,  r' = v sin(gamma),  theta' = v cos(gamma) / r,
        v' = -q cd_s_m - g sin(gamma),  gamma' = (lift_acc + q cl_s_m - (g - v^2/r) cos(gamma)) / v.
    phi and psi stay 0.0 (phi + 0.0 is +0.0 for phi = +-0.0)."""
    cos, sin = math.cos, math.sin
    half_rho = 0.5 * rho  # 0.5 * rho * v * v evaluates (0.5 * rho) first
    constant_g = gravity_model == GRAVITY_CONSTANT
    half = 0.5 * dt
    r, _theta, _phi, v, gamma, _psi = x

    q = half_rho * v * v
    g = g0 if constant_g else mu / (r * r)
    cg, sg = cos(gamma), sin(gamma)
    a0, a1 = v * sg, v * cg / r
    a3, a4 = -(q * cd_s_m) - g * sg, (lift_acc + q * cl_s_m - (g - v * (v / r)) * cg) / v

    r1, v1, gamma1 = r + half * a0, v + half * a3, gamma + half * a4
    q = half_rho * v1 * v1
    g = g0 if constant_g else mu / (r1 * r1)
    cg, sg = cos(gamma1), sin(gamma1)
    b0, b1 = v1 * sg, v1 * cg / r1
    b3, b4 = -(q * cd_s_m) - g * sg, (lift_acc + q * cl_s_m - (g - v1 * (v1 / r1)) * cg) / v1

    r1, v1, gamma1 = r + half * b0, v + half * b3, gamma + half * b4
    q = half_rho * v1 * v1
    g = g0 if constant_g else mu / (r1 * r1)
    cg, sg = cos(gamma1), sin(gamma1)
    c0, c1 = v1 * sg, v1 * cg / r1
    c3, c4 = -(q * cd_s_m) - g * sg, (lift_acc + q * cl_s_m - (g - v1 * (v1 / r1)) * cg) / v1

    r1, v1, gamma1 = r + dt * c0, v + dt * c3, gamma + dt * c4
    q = half_rho * v1 * v1
    g = g0 if constant_g else mu / (r1 * r1)
    cg, sg = cos(gamma1), sin(gamma1)
    d0, d1 = v1 * sg, v1 * cg / r1
    d3, d4 = -(q * cd_s_m) - g * sg, (lift_acc + q * cl_s_m - (g - v1 * (v1 / r1)) * cg) / v1

    s = dt / 6.0
    return [r + s * (a0 + 2.0 * b0 + 2.0 * c0 + d0), x[1] + s * (a1 + 2.0 * b1 + 2.0 * c1 + d1), 0.0,
            v + s * (a3 + 2.0 * b3 + 2.0 * c3 + d3), gamma + s * (a4 + 2.0 * b4 + 2.0 * c4 + d4), 0.0]


def integrate(x, dt, max_substep, args):
    """Advance x over dt (s) by RK4 in equal substeps no longer than max_substep (s)."""
    n = max(1, math.ceil(dt / max_substep - 1e-9))
    h = dt / n
    for _ in range(n):
        x = rk4_step(x, h, args)
    return x
