"""The NPC predictor's flight (`npc.fly`) compiled from C: the same operations in the same order.

`npc.fly` integrates the planar model by RK4 to the exit crossing 400 times per run of the NPC
law; in Python that is nine tenths of the run. `SOURCE` is the same loop in C: every expression
is written with the association Python evaluates (left to right, `a + 2.0 * b + 2.0 * c + d`
as ((a + 2b) + 2c) + d), the exponential, sine and cosine are the C library's, which Python's
`math` calls too, and it is compiled with `c_kernels.FLAGS` (no fused multiply-add, no builtin
replacement of the library calls, no fast math), so both give the same numbers to the bit
(`tests/studies/test_npc_kernel.py` compares them).

Compiled on first use into the FMU cache's `kernels` folder and loaded by `c_kernels.load`;
without a compiler, `flight` returns None and `npc.fly` runs its Python loop.
"""

import ctypes
from functools import lru_cache
from pathlib import Path

from aotv_cosim.guidance import c_kernels

SOURCE = r"""
#include <math.h>

/* Lift profile of npc.lift_profile: phase 1 linear from u_c at t_k to u_final at t_switch. */
static double lift(double t, double t_k, double u_c, double t_switch, double u_final)
{
    if (t_k >= t_switch)
        return u_c;
    if (t >= t_switch)
        return u_final;
    return u_c + (u_final - u_c) * (t - t_k) / (t_switch - t_k);
}

/* Rates of r, v, gamma of point_mass._rates' planar branch (bank 0, cl_s_m 0), with the density
   scale * rho_ref exp(-(h - h_ref)/H) at r. */
static void rates(double r, double v, double gamma, double u, const double *m, double *out)
{
    double rho = m[0] * (m[1] * exp(-((r - m[5]) - m[2]) / m[3]));
    double q_over_m = 0.5 * rho * v * v;
    double lift_acc = u + q_over_m * 0.0;
    double drag = q_over_m * m[4];
    double g = m[6] == 0.0 ? m[7] : m[8] / (r * r);
    double cg = cos(gamma), sg = sin(gamma);
    double v_over_r = v / r;
    out[0] = v * sg;
    out[1] = -drag - g * sg;
    out[2] = (lift_acc - (g - v * v_over_r) * cg) / v;
}

/* p: t_k, h0, v0, gamma0, u_c, scale, rho_ref, h_ref, scale_height, cd_s_m, r_earth,
   gravity_model, g0, mu, h_exit, step, horizon, h_floor, t_switch, u_final.
   out: time, h, v, gamma at the exit crossing (returns 1) or where the flight ended (returns 0). */
int aotv_npc_fly(const double *p, double *out)
{
    const double t_k = p[0], u_c = p[4], r_earth = p[10], h_exit = p[14], step = p[15];
    const double t_switch = p[18], u_final = p[19];
    const double m[9] = {p[5], p[6], p[7], p[8], p[9], r_earth, p[11], p[12], p[13]};
    double r = r_earth + p[1], v = p[2], gamma = p[3];
    double t = t_k, t_end = t_k + p[16];
    const double h_exit_r = r_earth + h_exit, floor_r = r_earth + p[17];
    double a[3], b[3], c[3], d[3];
    while (t < t_end) {
        double dt = (t_end - t < step) ? t_end - t : step;
        double half = 0.5 * dt;
        double u_half = lift(t + half, t_k, u_c, t_switch, u_final);
        rates(r, v, gamma, lift(t, t_k, u_c, t_switch, u_final), m, a);
        rates(r + half * a[0], v + half * a[1], gamma + half * a[2], u_half, m, b);
        rates(r + half * b[0], v + half * b[1], gamma + half * b[2], u_half, m, c);
        rates(r + dt * c[0], v + dt * c[1], gamma + dt * c[2],
              lift(t + dt, t_k, u_c, t_switch, u_final), m, d);
        double s = dt / 6.0;
        double r_new = r + s * (a[0] + 2.0 * b[0] + 2.0 * c[0] + d[0]);
        double v_new = v + s * (a[1] + 2.0 * b[1] + 2.0 * c[1] + d[1]);
        double gamma_new = gamma + s * (a[2] + 2.0 * b[2] + 2.0 * c[2] + d[2]);
        if (r_new >= h_exit_r && h_exit_r > r && gamma_new > 0.0) {
            double f = (h_exit_r - r) / (r_new - r);
            out[0] = t + f * dt;
            out[1] = h_exit;
            out[2] = v + f * (v_new - v);
            out[3] = gamma + f * (gamma_new - gamma);
            return 1;
        }
        t = t + dt;
        r = r_new;
        v = v_new;
        gamma = gamma_new;
        if (r < floor_r)
            break;
    }
    out[0] = t;
    out[1] = r - r_earth;
    out[2] = v;
    out[3] = gamma;
    return 0;
}
"""

LIBRARY = c_kernels.library_name("aotv_npc", SOURCE)
"""File name of the compiled kernel (changes with the source and the options). An FMU build may
bundle it as resources/aotv_cosim/guidance/LIBRARY."""


@lru_cache(maxsize=1)
def _function():
    library = c_kernels.load(SOURCE, LIBRARY, Path(__file__))
    if library is None:
        return None
    function = library.aotv_npc_fly
    function.argtypes = (ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_double))
    function.restype = ctypes.c_int
    return function


def available() -> bool:
    """Whether the compiled kernel can be used here."""
    return _function() is not None


_PARAMETERS = ctypes.c_double * 20


def flight(parameters):
    """(exited, time s, h m, v m/s, gamma rad) of the compiled flight for the 20 `parameters`
    (the order of `SOURCE`'s aotv_npc_fly), or None when the kernel is not available."""
    function = _function()
    if function is None:
        return None
    out = (ctypes.c_double * 4)()
    exited = function(_PARAMETERS(*parameters), out)
    return bool(exited), out[0], out[1], out[2], out[3]
