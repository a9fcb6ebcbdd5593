"""Campaign statistics: percentiles per column, and the 3-sigma ellipse of a scatter."""

import math

import numpy as np

PERCENTILES = (1, 5, 50, 95, 99)


def _numeric(rows, name):
    values = np.array([r[name] for r in rows if r["status"] == "completed"], dtype=float)
    return values[np.isfinite(values)]


def statistics(rows, columns) -> dict:
    """{column: {n, mean, std, min, max, p1..p99}} over the completed runs."""
    stats = {}
    for name in columns:
        if name in ("run", "status", "error", "outcome", "outcome.reason"):
            continue
        x = _numeric(rows, name)
        if len(x):
            stats[name] = {"n": int(len(x)), "mean": float(x.mean()), "std": float(x.std(ddof=1)) if len(x) > 1 else 0.0,
                           "min": float(x.min()), "max": float(x.max()),
                           **{f"p{p}": float(v) for p, v in zip(PERCENTILES, np.percentile(x, PERCENTILES))}}
    return stats


def ellipse_3sigma(x, y, points=200):
    """(xs, ys) of the 3-sigma ellipse of the sample covariance of (x, y)."""
    center = np.array([x.mean(), y.mean()])
    values, vectors = np.linalg.eigh(np.cov(np.vstack([x, y])))
    angle = np.linspace(0.0, 2.0 * math.pi, points)
    circle = np.vstack([np.cos(angle), np.sin(angle)]) * 3.0 * np.sqrt(np.maximum(values, 0.0))[:, None]
    curve = vectors @ circle + center[:, None]
    return curve[0], curve[1]

