"""US76 density in C (`physics.us76.density`), the source the compiled predictors include.

`SOURCE` is C text that a kernel's source begins with (`npc_bank_kernel`, `oracle_kernel`): a
`struct us76` of the standard's constants and tables, `us76_unpack` filling it from the array
`tables()` gives (the values of `physics.us76`, not retyped), and `us76_density(z, atm)`, the
density at geometric altitude z (m) with the operations of `us76.density` in the same order
(its layers below 86 km: `us76.lower`; above, the natural cubic spline in ln rho of
`us76.upper_density`, bisect_left for the interval, the last interval's exponential above the
table). Float `**` is the C library's pow (what CPython's float power calls for a positive base;
`a ** 3` is pow(a, 3.0)), exp is the C library's; compiled with `c_kernels.FLAGS`, the density
equals the Python function's to the bit (`tests/studies/test_npc_bank_kernel.py`,
`tests/studies/test_oracle_kernel.py`).
"""

import ctypes
from functools import lru_cache

from aotv_cosim.physics import us76

SOURCE = r"""
#include <math.h>

/* The US76 constants and tables of physics.us76 (us76_unpack). */
struct us76 {
    double r0, gmr, m0, r_star, z_86;
    int n_bases, n_nodes;
    const double *bases, *nodes, *ln_rho, *m2;
};

/* u: R0, GMR, M0, R_STAR, Z_86, n_bases, bases (H_b, T_Mb, P_b, L_b) x n_bases, n_nodes, nodes,
   ln rho, second derivatives (n_nodes each). */
static void us76_unpack(struct us76 *a, const double *u)
{
    a->r0 = u[0]; a->gmr = u[1]; a->m0 = u[2]; a->r_star = u[3]; a->z_86 = u[4];
    a->n_bases = (int)u[5];
    a->bases = u + 6;
    a->n_nodes = (int)u[6 + 4 * a->n_bases];
    a->nodes = u + 7 + 4 * a->n_bases;
    a->ln_rho = a->nodes + a->n_nodes;
    a->m2 = a->ln_rho + a->n_nodes;
}

/* us76.lower(z)[2]: the layer of the geopotential altitude, hydrostatic pressure, density. */
static double us76_lower(double z, const struct us76 *a)
{
    double h = a->r0 * z / (a->r0 + z);
    int k = a->n_bases - 1;
    while (k > 0 && h < a->bases[4 * k])
        k--;
    const double *b = a->bases + 4 * k;
    double h_b = b[0], t_b = b[1], p_b = b[2], lapse = b[3], t, p;
    if (lapse == 0.0) {
        t = t_b;
        p = p_b * exp(-a->gmr * (h - h_b) / t_b);
    } else {
        t = t_b + lapse * (h - h_b);
        p = p_b * pow(t_b / t, a->gmr / lapse);
    }
    return p * a->m0 / (a->r_star * t);
}

/* us76.upper_density: natural cubic spline in ln rho (bisect_left for the interval). */
static double us76_upper(double z, const struct us76 *a)
{
    const double *nodes = a->nodes, *y = a->ln_rho, *m2 = a->m2;
    int n = a->n_nodes, lo = 0, hi = n;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (nodes[mid] < z)
            lo = mid + 1;
        else
            hi = mid;
    }
    int k = lo - 1;
    if (k < 0)
        k = 0;
    if (k > n - 2)
        k = n - 2;
    double h = nodes[k + 1] - nodes[k];
    if (z >= nodes[n - 1]) {
        double slope = (y[n - 1] - y[n - 2]) / h;
        return exp(y[n - 1] + slope * (z - nodes[n - 1]));
    }
    double ca = (nodes[k + 1] - z) / h;
    double cb = 1.0 - ca;
    double ln_rho = ca * y[k] + cb * y[k + 1]
                    + ((pow(ca, 3.0) - ca) * m2[k] + (pow(cb, 3.0) - cb) * m2[k + 1]) * h * h / 6.0;
    return exp(ln_rho);
}

/* us76.density(z). */
static double us76_density(double z, const struct us76 *a)
{
    return z <= a->z_86 ? us76_lower(z, a) : us76_upper(z, a);
}
"""


@lru_cache(maxsize=1)
def tables():
    """The US76 constants and tables in the layout `us76_unpack` reads (ctypes array)."""
    bases = us76._bases()
    nodes, ln_rho, m2 = us76._spline()
    values = [us76.R0, us76.GMR, us76.M0, us76.R_STAR, us76.Z_86, float(len(bases))]
    values += [float(v) for base in bases for v in base]
    values += [float(len(nodes)), *map(float, nodes), *map(float, ln_rho), *map(float, m2)]
    return (ctypes.c_double * len(values))(*values)
