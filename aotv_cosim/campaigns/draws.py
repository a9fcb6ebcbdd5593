"""Dispersed parameter values of each run, from the campaign seed and the run's index."""

import numpy as np


def run_seed(campaign_seed: int, run: int) -> np.random.SeedSequence:
    """The seed of run `run`: child `run` of SeedSequence(campaign_seed), as `spawn` makes it."""
    return np.random.SeedSequence(campaign_seed, spawn_key=(run,))


def draw(dispersions, campaign_seed: int, run: int) -> dict:
    """{'comp.var': value} for one run: each dispersion sampled in declaration order."""
    rng = np.random.default_rng(run_seed(campaign_seed, run))
    return {d.signal: sample(d, rng) for d in dispersions}


def sample(dispersion, rng) -> float:
    """One draw of `dispersion` (`model.scenario.Dispersion`) from the numpy Generator `rng`."""
    d = dispersion
    if d.kind == "uniform":
        return float(rng.uniform(d.low, d.high))
    if d.kind == "normal":
        return float(rng.normal(d.mean, d.std))
    from scipy.stats import truncnorm

    a, b = (d.low - d.mean) / d.std, (d.high - d.mean) / d.std
    return float(truncnorm.rvs(a, b, loc=d.mean, scale=d.std, random_state=rng))
