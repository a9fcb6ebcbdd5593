"""Random density profiles correlated in altitude, seeded per run (GRAM-style dispersions).

A Monte Carlo run flies the model density times exp(delta(h)): delta is a zero-mean Gaussian
process in altitude with standard deviation `sigma` (relative, dimensionless: ln-density) and the
exponential correlation E[delta(h1) delta(h2)] = sigma^2 exp(-|h1 - h2| / L), L the correlation
length in m. Earth-GRAM and Mars-GRAM give their perturbations the same form (a relative density
deviation whose altitude correlation is set by a scale length); here it is the first-order
Gauss-Markov process sampled exactly on a grid of `GRID_STEP` m,
    x_0 ~ N(0, 1),   x_{k+1} = a x_k + sqrt(1 - a^2) w_k,   a = exp(-GRID_STEP / L),  w_k ~ N(0, 1),
and interpolated linearly in altitude between the nodes; delta = sigma x. The log-normal factor
keeps the density positive whatever sigma (its median is 1, its mean exp(sigma^2 / 2)).

The normal draws come from numpy.random.Generator(PCG64) seeded with the integer `seed`, so one
seed gives one profile, whatever the communication step. A constant scale factor (the
Atmosphere's density_factor) multiplies the result separately. numpy only (bundled into the FMUs).
"""

import math
from functools import lru_cache

import numpy as np

GRID_STEP = 500.0
"""Altitude step of the sampled process, m (well under the correlation lengths used, >= 5 km)."""
GRID_TOP = 300000.0
"""Top of the sampled altitudes, m; above it (and below 0) the end values are held."""


@lru_cache(maxsize=8)
def _nodes(length: float, seed: int):
    """The unit-variance process x at the grid nodes 0, GRID_STEP, ..., GRID_TOP (tuple)."""
    n = round(GRID_TOP / GRID_STEP) + 1
    w = np.random.default_rng(seed).standard_normal(n)
    a = math.exp(-GRID_STEP / length)
    b = math.sqrt(1.0 - a * a)
    x = np.empty(n)
    x[0] = w[0]
    for k in range(1, n):
        x[k] = a * x[k - 1] + b * w[k]
    return tuple(x)


def profile_factor(h: float, sigma: float, length: float, seed: int) -> float:
    """Density multiplier exp(sigma x(h)) of the profile `seed` at altitude h (m); 1 when sigma is
    0. length: correlation length L (m, > 0); seed: integer >= 0."""
    if sigma == 0.0:
        return 1.0
    x = _nodes(float(length), int(seed))
    s = min(max(h, 0.0), GRID_TOP) / GRID_STEP
    k = min(int(s), len(x) - 2)
    f = s - k
    return math.exp(sigma * ((1.0 - f) * x[k] + f * x[k + 1]))
