"""Campaign statistics: a column's values over the completed runs and their sample statistics
(summary.json `statistics`, the report's 3-sigma table), and the 3-sigma ellipse of a scatter."""

import math

import numpy as np

from aotv_cosim.status import Status

PERCENTILES = (1, 5, 50, 95, 99)
"""Percentiles of summary.json's `statistics`."""
TEXT_COLUMNS = ("run", "status", "error", "outcome", "outcome.reason")
"""Row columns that hold no measured number."""


def completed_values(rows, name) -> np.ndarray:
    """The finite values of column `name` over the completed runs."""
    x = np.array([r[name] for r in rows if r["status"] == Status.COMPLETED], dtype=float)
    return x[np.isfinite(x)]


def sample_statistics(x: np.ndarray, percentiles) -> dict:
    """{n, mean, std (sample; 0 for one value), min, max, p<q> for each of the `percentiles` q}
    of the values `x` (not empty), in their unit. Values near the float range may give an infinite
    mean or std (the result files write it as text), without a warning."""
    with np.errstate(over="ignore", invalid="ignore"):
        return {"n": len(x), "mean": float(x.mean()), "std": float(x.std(ddof=1)) if len(x) > 1 else 0.0,
                "min": float(x.min()), "max": float(x.max()),
                **{f"p{p:g}": float(v) for p, v in zip(percentiles, np.percentile(x, percentiles))}}


def statistics(rows, columns) -> dict:
    """{column: {n, mean, std, min, max, p1..p99}} over the completed runs (a column without a
    finite value is left out)."""
    stats = {}
    for name in columns:
        x = completed_values(rows, name) if name not in TEXT_COLUMNS else np.array([])
        if len(x):
            stats[name] = sample_statistics(x, PERCENTILES)
    return stats


def ellipse_3sigma(x, y, points=200):
    """(xs, ys) of the 3-sigma ellipse of the sample covariance of (x, y)."""
    center = np.array([x.mean(), y.mean()])
    values, vectors = np.linalg.eigh(np.cov(np.vstack([x, y])))
    angle = np.linspace(0.0, 2.0 * math.pi, points)
    circle = np.vstack([np.cos(angle), np.sin(angle)]) * 3.0 * np.sqrt(np.maximum(values, 0.0))[:, None]
    curve = vectors @ circle + center[:, None]
    return curve[0], curve[1]

