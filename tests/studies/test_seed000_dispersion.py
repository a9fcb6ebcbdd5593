"""Density dispersions of seed 000 Chs. 7-8 (K about +-20 % of nominal), physics.atmosphere."""

import numpy as np
import pytest

from aotv_cosim.physics.atmosphere import density_dispersion


def _history(times, **kw):
    return np.array([density_dispersion(t, **kw) for t in times])


def test_constant_factor():
    """A constant multiplier for the whole run (extraction Sec. 8 item 15 (i))."""
    assert density_dispersion(0.0, factor=0.8) == 0.8
    assert density_dispersion(123.4, factor=1.2) == 1.2


def test_noise_is_bounded_uniform_and_piecewise_constant():
    """+-20 % piecewise-constant uniform noise held on each interval (item 15 (ii)): within
    [0.8, 1.2), constant inside an interval, mean near 1 and spread of a uniform (std 0.2/sqrt 3)."""
    kw = dict(amplitude=0.2, interval=0.5, seed=3)
    samples = _history(np.arange(4000) * 0.5 + 0.25, **kw)
    assert samples.min() >= 0.8 and samples.max() < 1.2
    assert samples.mean() == pytest.approx(1.0, abs=0.01)
    assert samples.std() == pytest.approx(0.2 / np.sqrt(3.0), rel=0.05)
    inside = _history([10.0, 10.1, 10.2, 10.3, 10.4999], **kw)
    assert np.all(inside == inside[0])
    assert density_dispersion(10.5, **kw) != inside[0]


def test_history_does_not_depend_on_the_step():
    """Counter-based draws: a 0.1 s and a 0.05 s sampling of the same seed agree at every common
    time, including times like 0.3 s whose quotient by the interval is inexact in binary."""
    kw = dict(amplitude=0.2, interval=0.1, seed=11)
    coarse = _history(np.arange(0, 3001) * 0.1, **kw)
    fine = _history(np.arange(0, 6001) * 0.05, **kw)
    np.testing.assert_array_equal(coarse, fine[::2])
    assert density_dispersion(0.3, **kw) == density_dispersion(0.35, **kw)


def test_seeds_differ_and_repeat():
    kw = dict(amplitude=0.2, interval=1.0)
    times = np.arange(50) + 0.5
    assert np.array_equal(_history(times, seed=1, **kw), _history(times, seed=1, **kw))
    assert not np.array_equal(_history(times, seed=1, **kw), _history(times, seed=2, **kw))


def test_factor_and_noise_combine():
    kw = dict(amplitude=0.2, interval=1.0, seed=5)
    assert density_dispersion(2.5, factor=0.8, **kw) == pytest.approx(0.8 * density_dispersion(2.5, **kw))
