"""U.S. Standard Atmosphere 1976 (NOAA/NASA/USAF, NOAA-S/T 76-1562, 1976): temperature and density.

0 to 86 km (geometric): computed from the standard's own definitions. Seven layers linear in
molecular-scale temperature T_M against geopotential altitude H = r0 z / (r0 + z) (r0 =
6356.766 km), bases at H_b = 0, 11, 20, 32, 47, 51, 71 km' with lapse rates -6.5, 0, +1, +2.8, 0,
-2.8, -2.0 K/km', T_M = 288.15 K and P = 101325 Pa at sea level. Hydrostatic pressure
    P = P_b (T_Mb / T_M)^(g0' M0 / (R* L_b))       (L_b != 0),
    P = P_b exp(-g0' M0 (H - H_b) / (R* T_Mb))      (L_b = 0),
with g0' = 9.80665 m^2/(s^2 m'), M0 = 28.9644 kg/kmol, R* = 8314.32 J/(kmol K); density
rho = P M0 / (R* T_M). The kinetic temperature T equals T_M except between 80 and 86 km, where
T = T_M M/M0 with the standard's tabulated ratio M/M0 (1 at 80 km to 0.999579 at 86 km, linear in
between here: the standard gives it every 0.5 km, its change over 6 km is 4.2e-4).

Above 86 km: the standard's kinetic temperature is defined in four segments (isothermal
186.8673 K to 91 km; elliptical to 110 km; +12 K/km to 120 km; exponential toward 1000 K above)
and evaluated from those definitions here. The density there comes from the diffusion of the
separate species in the standard; instead of integrating those equations, it is interpolated in
its published table (the standard's Table I values at the altitudes of `UPPER_TABLE`) by a natural
cubic spline in ln(rho) against altitude: exact at the nodes (7-10 km apart up to 200 km); between
them it differs from the standard's finer table by up to about 0.4 % (110 km: 9.675e-8 against
9.708e-8 kg/m^3).

Units: SI (m, K, Pa, kg/m^3). numpy only (bundled into the FMUs).
"""

import bisect
import math
from functools import lru_cache

import numpy as np

R0 = 6356766.0
"""Earth radius of the geopotential altitude, m."""
G0 = 9.80665
"""Sea-level gravity, m/s^2 (and the geopotential unit g0')."""
M0 = 28.9644
"""Sea-level mean molecular weight, kg/kmol."""
R_STAR = 8314.32
"""Universal gas constant of the standard, J/(kmol K)."""
GMR = G0 * M0 / R_STAR
"""g0' M0 / R*, K/m: the hydrostatic constant (34.1632 K/km)."""

LAYERS = (  # (base geopotential altitude m', lapse rate K/m')
    (0.0, -6.5e-3), (11000.0, 0.0), (20000.0, 1.0e-3), (32000.0, 2.8e-3), (47000.0, 0.0),
    (51000.0, -2.8e-3), (71000.0, -2.0e-3))
"""The standard's layers below 84.852 km' (86 km geometric)."""
Z_86 = 86000.0
"""Top of the computed region, geometric m (84.852 km' geopotential)."""

UPPER_TABLE = (  # (geometric altitude m, density kg/m^3): the standard's Table I
    (86000.0, 6.9579e-06), (93000.0, 1.9997e-06), (100000.0, 5.6041e-07), (107000.0, 1.6426e-07),
    (114000.0, 4.9752e-08), (121000.0, 1.9768e-08), (128000.0, 9.7173e-09), (135000.0, 5.4652e-09),
    (142000.0, 3.3580e-09), (150000.0, 2.0757e-09), (160000.0, 1.2332e-09), (170000.0, 7.8155e-10),
    (180000.0, 5.1944e-10), (190000.0, 3.5808e-10), (200000.0, 2.5409e-10), (250000.0, 6.0732e-11),
    (300000.0, 1.9160e-11), (400000.0, 2.8031e-12), (500000.0, 5.2159e-13), (600000.0, 1.1369e-13),
    (700000.0, 3.0698e-14), (800000.0, 1.1361e-14), (1000000.0, 3.5614e-15))
"""Published US76 densities above 86 km, interpolated (module docstring)."""


def geopotential(z: float) -> float:
    """Geopotential altitude H = r0 z / (r0 + z), m', of geometric altitude z (m)."""
    return R0 * z / (R0 + z)


@lru_cache(maxsize=1)
def _bases():
    """(H_b m', T_Mb K, P_b Pa, L_b K/m') of every layer, P_b integrated from sea level."""
    t, p = 288.15, 101325.0
    out = []
    for k, (h_b, lapse) in enumerate(LAYERS):
        out.append((h_b, t, p, lapse))
        top = LAYERS[k + 1][0] if k + 1 < len(LAYERS) else geopotential(Z_86)
        t, p = _layer(h_b, t, p, lapse, top)
    return tuple(out)


def _layer(h_b, t_b, p_b, lapse, h):
    """(T_M K, P Pa) at geopotential h (m') inside the layer with base (h_b, t_b, p_b, lapse)."""
    if lapse == 0.0:
        return t_b, p_b * math.exp(-GMR * (h - h_b) / t_b)
    t = t_b + lapse * (h - h_b)
    return t, p_b * (t_b / t) ** (GMR / lapse)


def lower(z: float):
    """(molecular-scale temperature T_M K, pressure P Pa, density kg/m^3) at geometric altitude
    z (m), 0 <= z <= 86 km (below 0 the first layer is extended)."""
    h = geopotential(z)
    bases = _bases()
    k = len(bases) - 1
    while k > 0 and h < bases[k][0]:
        k -= 1
    h_b, t_b, p_b, lapse = bases[k]
    t_m, p = _layer(h_b, t_b, p_b, lapse, h)
    return t_m, p, p * M0 / (R_STAR * t_m)


def molecular_weight_ratio(z: float) -> float:
    """M/M0 of the standard between 80 and 86 km (linear from 1 to 0.999579), 1 below."""
    if z <= 80000.0:
        return 1.0
    return 1.0 - 0.000421 * min(z - 80000.0, 6000.0) / 6000.0


def upper_temperature(z: float) -> float:
    """Kinetic temperature (K) of the standard above 86 km (geometric z, m), its four segments."""
    zk = z / 1000.0
    if zk <= 91.0:
        return 186.8673
    if zk <= 110.0:
        x = (zk - 91.0) / 19.9429
        return 263.1905 - 76.3232 * math.sqrt(max(0.0, 1.0 - x * x))
    if zk <= 120.0:
        return 240.0 + 12.0 * (zk - 110.0)
    xi = (zk - 120.0) * (R0 / 1000.0 + 120.0) / (R0 / 1000.0 + zk)
    return 1000.0 - 640.0 * math.exp(-0.01875 * xi)


@lru_cache(maxsize=1)
def _spline():
    """(nodes m, ln rho, second derivatives) of the natural cubic spline through UPPER_TABLE."""
    z = np.array([a for a, _ in UPPER_TABLE])
    y = np.log([b for _, b in UPPER_TABLE])
    n = len(z)
    d = np.diff(z)
    a = np.zeros((n, n))
    rhs = np.zeros(n)
    a[0, 0] = a[-1, -1] = 1.0
    for i in range(1, n - 1):
        a[i, i - 1], a[i, i], a[i, i + 1] = d[i - 1], 2.0 * (d[i - 1] + d[i]), d[i]
        rhs[i] = 6.0 * ((y[i + 1] - y[i]) / d[i] - (y[i] - y[i - 1]) / d[i - 1])
    return tuple(z), tuple(y), tuple(np.linalg.solve(a, rhs))


def upper_density(z: float) -> float:
    """Density (kg/m^3) above 86 km from the standard's table (module docstring); above 1000 km
    the last interval's exponential is extended."""
    nodes, y, m2 = _spline()
    k = min(max(bisect.bisect_left(nodes, z) - 1, 0), len(nodes) - 2)
    h = nodes[k + 1] - nodes[k]
    if z >= nodes[-1]:
        slope = (y[-1] - y[-2]) / h
        return math.exp(y[-1] + slope * (z - nodes[-1]))
    a = (nodes[k + 1] - z) / h
    b = 1.0 - a
    ln_rho = a * y[k] + b * y[k + 1] + ((a ** 3 - a) * m2[k] + (b ** 3 - b) * m2[k + 1]) * h * h / 6.0
    return math.exp(ln_rho)


def density(z: float) -> float:
    """US76 density (kg/m^3) at geometric altitude z (m)."""
    if z <= Z_86:
        return lower(z)[2]
    return upper_density(z)


def temperature(z: float) -> float:
    """US76 kinetic temperature (K) at geometric altitude z (m)."""
    if z <= Z_86:
        return lower(z)[0] * molecular_weight_ratio(z)
    return upper_temperature(z)
