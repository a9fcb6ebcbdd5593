"""Dispersed parameter values of each run, from the campaign seed and the run's index."""

import numpy as np


def run_seed(campaign_seed: int, run: int) -> np.random.SeedSequence:
    """The seed of run `run`: child `run` of SeedSequence(campaign_seed), as `spawn` makes it."""
    return np.random.SeedSequence(campaign_seed, spawn_key=(run,))


def draw(dispersions, campaign_seed: int, run: int) -> dict:
    """{'comp.var': value} for one run: each dispersion sampled in declaration order."""
    rng = np.random.default_rng(run_seed(campaign_seed, run))
    return {d.signal: d.sample(rng) for d in dispersions}
