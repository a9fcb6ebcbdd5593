"""The bank-angle NPC's prediction (`npc_bank.predict`) compiled from C: the same operations in
the same order, US76 included.

A run of the bank NPC makes 600-800 predictions of 150-190 RK4 steps (AFE and AOTV sets); in
Python they are 97 % of its CPU (`npc_bank._rates`, `us76.density`). `SOURCE` is the whole
prediction loop of `npc_bank.fly` in C, one call per prediction: the RK4 stages of `_rk4`, the
rates of `_rates`, the model density of `BankModel.density` (US76 `physics.us76.density`: its
layers below 86 km and its ln-density spline above, or the exponential) times the density scale
(a constant or a `ScaleProfile` of altitude), the lift fraction of `vertical_fraction`, and the
exit, floor and horizon tests of `fly`. Every expression is written with the association Python
evaluates (left to right: `0.5 * rho * v * v` is ((0.5 rho) v) v), float `**` is the C library's
pow (what CPython's float power calls for a positive base; `a ** 3` is pow(a, 3.0), not a a a),
exp, sin and cos are the C library's (what `math` calls), and it is compiled with
`c_kernels.FLAGS` (no fused multiply-add, no builtin replacement of the library calls, no fast
math): the predictions equal the Python loop's to the bit (`tests/studies/test_npc_bank_kernel.py`
compares them over random states). The US76 density is `us76_kernel`'s C source, which the
oracle's kernel includes too; its tables (layer bases, spline nodes, ln rho and second
derivatives) are passed from `physics.us76`, not retyped.

Compiled on first use into the FMU cache's `kernels` folder (`c_kernels.load`); without a
compiler `flight` returns None and `npc_bank.fly` runs its Python loop.
"""

import ctypes
from array import array
from functools import lru_cache
from pathlib import Path

from aotv_cosim.guidance import c_kernels, us76_kernel

SOURCE = us76_kernel.SOURCE + r"""
/* The model of one prediction (npc_bank.BankModel, BankSettings, the scale and the US76 tables). */
struct model {
    double x, cl_s_m, cd_s_m, atmosphere, rho_ref, h_ref, scale_height, r_earth, gravity_model, g0, mu;
    double t_switch, cos_sigma_2;
    const double *scale_h, *scale_k;
    int n_scale, cursor;
    struct us76 atm;
};

/* ScaleProfile.at: piecewise linear through the nodes (altitudes strictly ascending), end values
   held; the interval is hunted from the last one (same interval as bisect_right). */
static double scale_at(double h, struct model *m)
{
    const double *a = m->scale_h, *k = m->scale_k;
    int n = m->n_scale;
    if (n == 1 || h <= a[0])
        return k[0];
    if (h >= a[n - 1])
        return k[n - 1];
    int j = m->cursor;
    while (j > 0 && h < a[j])
        j--;
    while (h >= a[j + 1])
        j++;
    m->cursor = j;
    return k[j] + (k[j + 1] - k[j]) * (h - a[j]) / (a[j + 1] - a[j]);
}

/* BankModel.density(h, scale). */
static double density(double h, struct model *m)
{
    double scale = scale_at(h, m);
    if (m->atmosphere == 1.0)
        return scale * us76_density(h, &m->atm);
    return scale * (m->rho_ref * exp(-(h - m->h_ref) / m->scale_height));
}

/* npc_bank._rates: planar (r, v, gamma) rates with the model's lift and drag. */
static void rates(double t, double r, double v, double gamma, struct model *m, double *out)
{
    double rho = density(r - m->r_earth, m);
    double q = 0.5 * rho * v * v;
    double g = m->gravity_model == 0.0 ? m->g0 : m->mu / (r * r);
    double cg = cos(gamma);
    double lift = q * m->cl_s_m * (t >= m->t_switch ? m->cos_sigma_2 : m->x);
    double sg = sin(gamma);
    out[0] = v * sg;
    out[1] = -q * m->cd_s_m - g * sg;
    out[2] = (lift - (g - v * v / r) * cg) / v;
}

/* p: t_k, h0, v0, gamma0, x, cl_s_m, cd_s_m, atmosphere, rho_ref, h_ref, scale_height, r_earth,
   gravity_model, g0, mu, h_exit, step, horizon, h_floor, t_switch, cos(sigma_2).
   scale_h, scale_k, n_scale: the density scale nodes (n_scale >= 1).
   u: the US76 tables (us76_unpack).
   out: time, h, v, gamma at the exit crossing (returns 1) or where the flight ended (returns 0). */
int aotv_npc_bank_fly(const double *p, const double *scale_h, const double *scale_k, int n_scale,
                      const double *u, double *out)
{
    struct model m;
    m.x = p[4]; m.cl_s_m = p[5]; m.cd_s_m = p[6]; m.atmosphere = p[7]; m.rho_ref = p[8];
    m.h_ref = p[9]; m.scale_height = p[10]; m.r_earth = p[11]; m.gravity_model = p[12];
    m.g0 = p[13]; m.mu = p[14]; m.t_switch = p[19]; m.cos_sigma_2 = p[20];
    m.scale_h = scale_h; m.scale_k = scale_k; m.n_scale = n_scale; m.cursor = 0;
    us76_unpack(&m.atm, u);

    const double t_k = p[0], r_earth = m.r_earth, h_exit = p[15], step = p[16];
    double y0 = r_earth + p[1], y1 = p[2], y2 = p[3];
    double t = t_k, t_end = t_k + p[17];
    const double exit_r = r_earth + h_exit, floor_r = r_earth + p[18];
    double a[3], b[3], c[3], d[3];
    while (t < t_end) {
        double dt = (t_end - t < step) ? t_end - t : step;
        rates(t, y0, y1, y2, &m, a);
        rates(t + 0.5 * dt, y0 + 0.5 * dt * a[0], y1 + 0.5 * dt * a[1], y2 + 0.5 * dt * a[2], &m, b);
        rates(t + 0.5 * dt, y0 + 0.5 * dt * b[0], y1 + 0.5 * dt * b[1], y2 + 0.5 * dt * b[2], &m, c);
        rates(t + dt, y0 + dt * c[0], y1 + dt * c[1], y2 + dt * c[2], &m, d);
        double n0 = y0 + dt / 6.0 * (a[0] + 2.0 * b[0] + 2.0 * c[0] + d[0]);
        double n1 = y1 + dt / 6.0 * (a[1] + 2.0 * b[1] + 2.0 * c[1] + d[1]);
        double n2 = y2 + dt / 6.0 * (a[2] + 2.0 * b[2] + 2.0 * c[2] + d[2]);
        if (n0 >= exit_r && exit_r > y0 && n2 > 0.0) {
            double f = (exit_r - y0) / (n0 - y0);
            out[0] = t + f * dt;
            out[1] = h_exit;
            out[2] = y1 + f * (n1 - y1);
            out[3] = y2 + f * (n2 - y2);
            return 1;
        }
        t = t + dt;
        y0 = n0;
        y1 = n1;
        y2 = n2;
        if (y0 < floor_r)
            break;
    }
    out[0] = t;
    out[1] = y0 - r_earth;
    out[2] = y1;
    out[3] = y2;
    return 0;
}
"""

LIBRARY = c_kernels.library_name("aotv_npc_bank", SOURCE)
"""File name of the compiled kernel (changes with the source and the options)."""


@lru_cache(maxsize=1)
def _function():
    library = c_kernels.load(SOURCE, LIBRARY, Path(__file__))
    if library is None:
        return None
    function = library.aotv_npc_bank_fly
    pointer = ctypes.POINTER(ctypes.c_double)
    function.argtypes = (pointer, pointer, pointer, ctypes.c_int, pointer, pointer)
    function.restype = ctypes.c_int
    return function


def available() -> bool:
    """Whether the compiled kernel can be used here."""
    return _function() is not None


_PARAMETERS = ctypes.c_double * 21


def scale_arrays(altitudes, scales):
    """The density scale nodes (altitudes m, strictly ascending; scales) as the ctypes arrays
    `flight` takes: (altitudes, scales, count); converted by `array` (a C loop), the ctypes arrays
    sharing and keeping its buffer."""
    n = len(scales)
    vector = ctypes.c_double * n
    return vector.from_buffer(array("d", altitudes)), vector.from_buffer(array("d", scales)), n


def flight(parameters, scale_nodes):
    """(exited, time s, h m, v m/s, gamma rad) of the compiled prediction for the 21 `parameters`
    (the order of `SOURCE`'s aotv_npc_bank_fly) and the density scale nodes (`scale_arrays`; one
    node: a constant scale), or None when the kernel is not available."""
    function = _function()
    if function is None:
        return None
    out = (ctypes.c_double * 4)()
    exited = function(_PARAMETERS(*parameters), *scale_nodes, us76_kernel.tables(), out)
    return bool(exited), out[0], out[1], out[2], out[3]
