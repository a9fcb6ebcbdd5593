"""The oracle's prediction (`oracle_bank.fly`) compiled from C: the co-simulated pass step for
step, the same operations in the same order.

A solve of the oracle flies 20 (AFE) to 180 (AOTV) predictions of some 400-500 communication
steps; in Python a step costs about 9 us and the predictions are nearly all of the solve.
`SOURCE` is `oracle_bank._fly_python` in C, one call per prediction (or per recorded trail):
the density of `TruthModel.density` (the model density, US76 from `us76_kernel` or the
exponential of `atmosphere.exponential_density`, times density_factor and the random profile's
factor of `density_profile.profile_factor`, whose nodes are passed from Python), the master's
extrapolation of the density and bank, the vehicle FMU's step (`point_mass.integrate` of
`rk4_step`: its planar case `_rk4_planar` and its general case `_rk4_general`; or, without
reversals, the three-state `oracle_bank._rk4`), the exit located by interpolation, the lateral
logic of `lateral.bank_sign`, and the BankActuator's `bank_actuator.step`. Every expression is
written with the association Python evaluates (left to right), the trigonometric, exp, pow and
fmod functions are the C library's (what `math` calls), and it is compiled with
`c_kernels.FLAGS` (no fused multiply-add, no builtin replacement, no fast math): the passes equal
the Python loop's to the bit (`tests/studies/test_oracle_kernel.py`).

Compiled on first use into the FMU cache's `kernels` folder (`c_kernels.load`); without a
compiler `flight` returns None and `oracle_bank.fly` runs its Python loop.
"""

import ctypes
from array import array
from functools import lru_cache
from pathlib import Path

from aotv_cosim.guidance import c_kernels, us76_kernel

SOURCE = us76_kernel.SOURCE + r"""
#include <stddef.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* The run's truth and the co-simulation's settings (oracle_bank.TruthModel, OracleSettings). */
struct model {
    double cl, cd, density_factor, profile_sigma, atmosphere, rho_ref, h_ref, scale_height;
    double rate_limit, accel_limit, r_earth, mu, period, h_exit, h_floor, horizon, deadband;
    double extrapolation, max_substep, g0, substep, grid_step, grid_top;
    const double *profile;
    int n_profile;
    struct us76 atm;
};

/* density_profile.profile_factor(h, sigma, length, seed) on the profile's nodes. */
static double profile_factor(double h, const struct model *m)
{
    if (m->profile_sigma == 0.0)
        return 1.0;
    double a = 0.0 > h ? 0.0 : h;
    a = m->grid_top < a ? m->grid_top : a;
    double s = a / m->grid_step;
    int k = (int)s;
    if (k > m->n_profile - 2)
        k = m->n_profile - 2;
    double f = s - k;
    return exp(m->profile_sigma * ((1.0 - f) * m->profile[k] + f * m->profile[k + 1]));
}

/* TruthModel.density(h): atmosphere.model_density times density_factor and the profile's factor. */
static double density(double h, const struct model *m)
{
    double rho;
    if (m->atmosphere == 1.0)
        rho = us76_density(h, &m->atm);
    else
        rho = m->rho_ref * exp(-(h - m->h_ref) / m->scale_height);
    return m->density_factor * rho * profile_factor(h, m);
}

/* point_mass._rk4_planar (lift_acc 0, inverse-square gravity) over dt, x updated. */
static void rk4_planar(double *x, double dt, double rho, const struct model *m)
{
    const double cl = m->cl, cd = m->cd, mu = m->mu, lift_acc = 0.0;
    double half_rho = 0.5 * rho, half = 0.5 * dt;
    double r = x[0], v = x[3], gamma = x[4];
    double q, g, cg, sg, r1, v1, gamma1;

    q = half_rho * v * v;
    g = mu / (r * r);
    cg = cos(gamma); sg = sin(gamma);
    double a0 = v * sg, a1 = v * cg / r;
    double a3 = -(q * cd) - g * sg, a4 = (lift_acc + q * cl - (g - v * (v / r)) * cg) / v;

    r1 = r + half * a0; v1 = v + half * a3; gamma1 = gamma + half * a4;
    q = half_rho * v1 * v1;
    g = mu / (r1 * r1);
    cg = cos(gamma1); sg = sin(gamma1);
    double b0 = v1 * sg, b1 = v1 * cg / r1;
    double b3 = -(q * cd) - g * sg, b4 = (lift_acc + q * cl - (g - v1 * (v1 / r1)) * cg) / v1;

    r1 = r + half * b0; v1 = v + half * b3; gamma1 = gamma + half * b4;
    q = half_rho * v1 * v1;
    g = mu / (r1 * r1);
    cg = cos(gamma1); sg = sin(gamma1);
    double c0 = v1 * sg, c1 = v1 * cg / r1;
    double c3 = -(q * cd) - g * sg, c4 = (lift_acc + q * cl - (g - v1 * (v1 / r1)) * cg) / v1;

    r1 = r + dt * c0; v1 = v + dt * c3; gamma1 = gamma + dt * c4;
    q = half_rho * v1 * v1;
    g = mu / (r1 * r1);
    cg = cos(gamma1); sg = sin(gamma1);
    double d0 = v1 * sg, d1 = v1 * cg / r1;
    double d3 = -(q * cd) - g * sg, d4 = (lift_acc + q * cl - (g - v1 * (v1 / r1)) * cg) / v1;

    double s = dt / 6.0;
    x[0] = r + s * (a0 + 2.0 * b0 + 2.0 * c0 + d0);
    x[1] = x[1] + s * (a1 + 2.0 * b1 + 2.0 * c1 + d1);
    x[2] = 0.0;
    x[3] = v + s * (a3 + 2.0 * b3 + 2.0 * c3 + d3);
    x[4] = gamma + s * (a4 + 2.0 * b4 + 2.0 * c4 + d4);
    x[5] = 0.0;
}

/* point_mass._rk4_general (lift_acc 0, inverse-square gravity, full heading equation) over dt,
   with cos(sigma) and sin(sigma) of the bank (the values the function takes at each call). */
static void rk4_general(double *x, double dt, double rho, double cos_sigma, double sin_sigma,
                        const struct model *m)
{
    const double cl = m->cl, cd = m->cd, mu = m->mu, lift_acc = 0.0;
    int level = sin_sigma == 0.0 && cos_sigma == 1.0;
    double half_rho = 0.5 * rho;
    double x0 = x[0], x1 = x[1], x2 = x[2], x3 = x[3], x4 = x[4], x5 = x[5];
    double r = x0, phi = x2, v = x3, gamma = x4, psi = x5;
    double k[4][6];
    const double f[3] = {0.5 * dt, 0.5 * dt, dt};
    for (int i = 0; i < 4; i++) {
        double q = half_rho * v * v;
        double lift = lift_acc + q * cl;
        double drag = q * cd;
        double g = mu / (r * r);
        double cg = cos(gamma), sg = sin(gamma);
        double v_over_r = v / r;
        double *ki = k[i];
        if (level && phi == 0.0 && psi == 0.0) {
            ki[0] = v * sg; ki[1] = v * cg / r; ki[2] = 0.0; ki[3] = -drag - g * sg;
            ki[4] = (lift - (g - v * v_over_r) * cg) / v; ki[5] = 0.0;
        } else {
            double cp = cos(psi), sp = sin(psi);
            double coupling = v * v_over_r * cg * cp * tan(phi);
            ki[0] = v * sg; ki[1] = v * cg * cp / (r * cos(phi)); ki[2] = v * cg * sp / r;
            ki[3] = -drag - g * sg;
            ki[4] = (lift * cos_sigma - (g - v * v_over_r) * cg) / v;
            ki[5] = (lift * sin_sigma / cg - coupling) / v;
        }
        if (i < 3) {
            r = x0 + f[i] * ki[0]; phi = x2 + f[i] * ki[2]; v = x3 + f[i] * ki[3];
            gamma = x4 + f[i] * ki[4]; psi = x5 + f[i] * ki[5];
        }
    }
    double s = dt / 6.0;
    const double x_old[6] = {x0, x1, x2, x3, x4, x5};
    for (int j = 0; j < 6; j++)
        x[j] = x_old[j] + s * (k[0][j] + 2.0 * k[1][j] + 2.0 * k[2][j] + k[3][j]);
}

/* oracle_bank._rk4: r, v, gamma over h with the bank's cosine held. */
static void rk4_planar3(double *x, double h, double rho, double cos_sigma, const struct model *m)
{
    const double cl = m->cl, cd = m->cd, mu = m->mu;
    double half = 0.5 * h;
    double y[3] = {x[0], x[3], x[4]}, k[4][3];
    double r = y[0], v = y[1], gamma = y[2];
    const double f[3] = {half, half, h};
    for (int i = 0; i < 4; i++) {
        double q = 0.5 * rho * v * v;
        double g = mu / (r * r);
        double cg = cos(gamma), sg = sin(gamma);
        k[i][0] = v * sg;
        k[i][1] = -(q * cd) - g * sg;
        k[i][2] = (q * cl * cos_sigma - (g - v * (v / r)) * cg) / v;
        if (i < 3) {
            r = y[0] + f[i] * k[i][0]; v = y[1] + f[i] * k[i][1]; gamma = y[2] + f[i] * k[i][2];
        }
    }
    double w = h / 6.0;
    x[0] = y[0] + w * (k[0][0] + 2.0 * k[1][0] + 2.0 * k[2][0] + k[3][0]);
    x[3] = y[1] + w * (k[0][1] + 2.0 * k[1][1] + 2.0 * k[2][1] + k[3][1]);
    x[4] = y[2] + w * (k[0][2] + 2.0 * k[1][2] + 2.0 * k[2][2] + k[3][2]);
}

/* oracle_bank._vehicle: the vehicle FMU's state after a communication step with rho, sigma held.
   The bank's cosine and sine, which each RK4 substep of point_mass takes again, are taken once. */
static void vehicle(double *x, double rho, double sigma, const struct model *m)
{
    double period = m->period;
    int n = (int)ceil(period / m->max_substep - 1e-9);
    if (n < 1)
        n = 1;
    if (m->deadband < M_PI) {
        double h = period / n, cos_sigma = 0.0, sin_sigma = 0.0;
        int trig = 0;
        for (int i = 0; i < n; i++) {
            if (x[2] == 0.0 && x[5] == 0.0 && sigma == 0.0) {
                rk4_planar(x, h, rho, m);
                continue;
            }
            if (!trig) {
                cos_sigma = cos(sigma);
                sin_sigma = sin(sigma);
                trig = 1;
            }
            rk4_general(x, h, rho, cos_sigma, sin_sigma, m);
        }
        return;
    }
    double cos_sigma = cos(sigma);
    for (int i = 0; i < n; i++)
        rk4_planar3(x, period / n, rho, cos_sigma, m);
}

/* fmod(y, 2 pi): y itself when |y| < 2 pi (fmod is exact: its quotient is then 0), the call else. */
static double fmod_two_pi(double y)
{
    return fabs(y) < 2.0 * M_PI ? y : fmod(y, 2.0 * M_PI);
}

/* bank_actuator.wrap. */
static double wrap(double angle)
{
    double a = fmod_two_pi(angle + M_PI);
    a = a <= 0.0 ? a + 2.0 * M_PI : a;
    return a - M_PI;
}

/* oracle_bank._actuator: bank_actuator.step unless at rest on the command. */
static void actuator(double *sigma_io, double *rate_io, double command, double dt, const struct model *m)
{
    double sigma = *sigma_io, rate = *rate_io;
    if (rate == 0.0 && sigma == command)
        return;
    int n = (int)ceil(dt / m->substep - 1e-9);
    if (n < 1)
        n = 1;
    double h = dt / n;
    const double pi = M_PI, two_pi = 2.0 * M_PI, rate_limit = m->rate_limit;
    double dv = m->accel_limit * h;
    double settle = dv * h, two_accel = 2.0 * m->accel_limit;
    for (int i = 0; i < n; i++) {
        double e = fmod_two_pi(command - sigma + pi);
        e = (e <= 0.0 ? e + two_pi : e) - pi;
        double size = fabs(e);
        if (size <= settle && fabs(rate) <= dv) {
            sigma = command;
            rate = 0.0;
            break;
        }
        double direction = e > 0.0 ? 1.0 : -1.0;
        double toward = rate * direction;
        double faster = toward + dv;
        if (!(faster < rate_limit))
            faster = rate_limit;
        if (toward <= 0.0 || faster * faster <= two_accel * (size - 0.5 * (toward + faster) * h))
            toward = faster;
        else if (toward * toward > two_accel * (size - toward * h))
            toward -= dv;
        double new_rate = direction * toward;
        sigma += 0.5 * (rate + new_rate) * h;
        rate = new_rate;
    }
    *sigma_io = wrap(sigma);
    *rate_io = rate;
}

/* lateral.bank_sign(previous, lateral.plane_error(phi, psi), deadband). */
static int bank_sign(int previous, double phi, double psi, double deadband)
{
    double error = psi + phi;
    previous = previous >= 0 ? 1 : -1;
    if (fabs(error) > deadband && previous * error > 0.0)
        return -previous;
    return previous;
}

/* p: cl_s_m, cd_s_m, density_factor, profile_sigma, atmosphere_model, rho_ref, h_ref, scale_height,
   rate_limit, accel_limit, r_earth, mu, command_period, h_exit, h_floor, horizon, deadband,
   input_extrapolation, max_substep, G0, bank_actuator.SUBSTEP, density_profile.GRID_STEP, GRID_TOP.
   profile, n_profile: the random profile's nodes (density_profile._nodes).
   u: the US76 tables (us76_unpack).
   fly: s1, t_switch, sigma_2.
   start: k, r, theta, phi, v, gamma, psi, sigma, rate, sigma one point earlier, density one point
   earlier, whether those two are known (0 at the point 0), sign (START_SIZE values).
   record, capacity: with record not NULL, the start of every step flown, START_SIZE values each,
   at most capacity of them (*recorded: how many).
   out: t, h, v, gamma at the exit crossing (returns 1) or where the flight ended (returns 0). */
int aotv_oracle_fly(const double *p, const double *profile, int n_profile, const double *u, const double *fly,
                    const double *start, double *record, int capacity, int *recorded, double *out)
{
    struct model m;
    m.cl = p[0]; m.cd = p[1]; m.density_factor = p[2]; m.profile_sigma = p[3]; m.atmosphere = p[4];
    m.rho_ref = p[5]; m.h_ref = p[6]; m.scale_height = p[7]; m.rate_limit = p[8]; m.accel_limit = p[9];
    m.r_earth = p[10]; m.mu = p[11]; m.period = p[12]; m.h_exit = p[13]; m.h_floor = p[14];
    m.horizon = p[15]; m.deadband = p[16]; m.extrapolation = p[17]; m.max_substep = p[18]; m.g0 = p[19];
    m.substep = p[20]; m.grid_step = p[21]; m.grid_top = p[22];
    m.profile = profile; m.n_profile = n_profile;
    us76_unpack(&m.atm, u);
    const double s1 = fly[0], t_switch = fly[1], sigma_2 = fly[2];
    const double period = m.period, r_earth = m.r_earth;

    long k = (long)start[0];
    double x[6] = {start[1], start[2], start[3], start[4], start[5], start[6]};
    double sigma = start[7], rate = start[8], sigma_before = start[9], rho_before = start[10];
    int known = start[11] != 0.0, sign = (int)start[12];
    if (k == 0) {
        sigma = sign * (0.0 < t_switch ? s1 : sigma_2);
        rate = 0.0;
    }
    int n = 0;
    while (k * period < m.horizon) {
        double t = k * period;
        if (record != NULL && n < capacity) {
            double *e = record + 13 * n++;
            e[0] = (double)k;
            for (int j = 0; j < 6; j++)
                e[1 + j] = x[j];
            e[7] = sigma; e[8] = rate; e[9] = sigma_before; e[10] = rho_before;
            e[11] = known ? 1.0 : 0.0; e[12] = (double)sign;
        }
        double h = x[0] - r_earth;
        double rho = density(h, &m);
        double rho_in = rho, sigma_in = sigma;
        if (m.extrapolation != 0.0 && known) {
            rho_in = rho + 0.5 * (rho - rho_before);
            sigma_in = sigma + 0.5 * (sigma - sigma_before);
        }
        double x_new[6] = {x[0], x[1], x[2], x[3], x[4], x[5]};
        vehicle(x_new, rho_in, sigma_in, &m);
        double h_new = x_new[0] - r_earth;
        if (h < m.h_exit && m.h_exit <= h_new) {
            double f = (m.h_exit - h) / (h_new - h);
            double gamma_exit = x[4] + f * (x_new[4] - x[4]);
            if (gamma_exit > 0.0) {
                out[0] = t + f * period;
                out[1] = h + f * (h_new - h);
                out[2] = x[3] + f * (x_new[3] - x[3]);
                out[3] = gamma_exit;
                if (recorded != NULL)
                    *recorded = n;
                return 1;
            }
        }
        sign = bank_sign(sign, x_new[2], x_new[5], m.deadband);
        double command = sign * (t + period < t_switch ? s1 : sigma_2);
        double sigma_new = sigma;
        actuator(&sigma_new, &rate, command, period, &m);
        k = k + 1;
        for (int j = 0; j < 6; j++)
            x[j] = x_new[j];
        sigma_before = sigma;
        rho_before = rho;
        known = 1;
        sigma = sigma_new;
        if (h_new < m.h_floor)
            break;
    }
    out[0] = k * period;
    out[1] = x[0] - r_earth;
    out[2] = x[3];
    out[3] = x[4];
    if (recorded != NULL)
        *recorded = n;
    return 0;
}
"""

LIBRARY = c_kernels.library_name("aotv_oracle", SOURCE)
"""File name of the compiled kernel (changes with the source and the options)."""

START_SIZE = 13
"""Values of a start (and of a recorded step) in the kernel's layout (`SOURCE`)."""


@lru_cache(maxsize=1)
def _function():
    library = c_kernels.load(SOURCE, LIBRARY, Path(__file__))
    if library is None:
        return None
    function = library.aotv_oracle_fly
    pointer = ctypes.POINTER(ctypes.c_double)
    function.argtypes = (pointer, pointer, ctypes.c_int, pointer, pointer, pointer, pointer, ctypes.c_int,
                         ctypes.POINTER(ctypes.c_int), pointer)
    function.restype = ctypes.c_int
    return function


def available() -> bool:
    """Whether the compiled kernel can be used here."""
    return _function() is not None


def parameters(values):
    """The 23 model and settings values of `SOURCE`'s `p` as a ctypes array."""
    return (ctypes.c_double * 23)(*values)


def profile_nodes(nodes):
    """The random profile's nodes (a sequence of floats) as (ctypes array, count)."""
    n = len(nodes)
    return (ctypes.c_double * n).from_buffer(array("d", nodes)), n


def flight(p, profile, start, s1: float, t_switch: float, sigma_2: float, capacity: int = 0):
    """(exited, t s, h m, v m/s, gamma rad, records) of the compiled pass, or None when the kernel
    is not available: `p` from `parameters`, `profile` from `profile_nodes`, `start` the
    START_SIZE values of the state flown from, the bank magnitude s1 (rad) before t_switch (s)
    and sigma_2 (rad) from it; with capacity > 0, records holds the start of every step flown (a
    flat array of START_SIZE values each, at most capacity steps), else None."""
    function = _function()
    if function is None:
        return None
    out = (ctypes.c_double * 4)()
    record = (ctypes.c_double * (START_SIZE * capacity))() if capacity else None
    recorded = ctypes.c_int(0)
    exited = function(p, *profile, us76_kernel.tables(), (ctypes.c_double * 3)(s1, t_switch, sigma_2),
                      (ctypes.c_double * START_SIZE)(*start), record, capacity, ctypes.byref(recorded), out)
    records = record[:START_SIZE * recorded.value] if record is not None else None
    return bool(exited), out[0], out[1], out[2], out[3], records
