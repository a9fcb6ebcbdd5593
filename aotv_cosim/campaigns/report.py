"""Campaign statistics and plots: percentiles per column, histograms, exit-state scatter."""

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


def plots(out_dir, rows, scenario) -> list:
    """histograms.png (dispersed values and exit/final values) and scatter.png; returns file names."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    at = "exit" if scenario.stop_conditions else "final"
    names = [f"dispersed.{d.signal}" for d in scenario.dispersions]
    names += [f"{at}.{s}" for s in scenario.record]
    names = [n for n in names if len(_numeric(rows, n)) > 1]
    files = []
    if names:
        ncols = min(3, len(names))
        nrows = math.ceil(len(names) / ncols)
        fig, axes = plt.subplots(nrows, ncols, figsize=(4.2 * ncols, 2.8 * nrows), squeeze=False)
        for ax, name in zip(axes.flat, names):
            ax.hist(_numeric(rows, name), bins=30)
            ax.set_title(name, fontsize=9)
        for ax in list(axes.flat)[len(names):]:
            ax.axis("off")
        fig.tight_layout()
        fig.savefig(out_dir / "histograms.png", dpi=90)
        plt.close(fig)
        files.append("histograms.png")
    pair = scenario.scatter or scenario.record[:2]
    if len(pair) == 2:
        x, y = (np.array([r[f"{at}.{s}"] for r in rows if r["status"] == "completed"], dtype=float)
                for s in pair)
        keep = np.isfinite(x) & np.isfinite(y)
        x, y = x[keep], y[keep]
        if len(x) > 2:
            fig, ax = plt.subplots(figsize=(5.5, 4.5))
            ax.plot(x, y, ".", ms=3, alpha=0.6, label=f"{len(x)} runs")
            ax.plot(*ellipse_3sigma(x, y), "r-", lw=1.2, label="3-sigma ellipse")
            ax.set_xlabel(f"{at} {pair[0]}")
            ax.set_ylabel(f"{at} {pair[1]}")
            ax.legend(fontsize=8)
            fig.tight_layout()
            fig.savefig(out_dir / "scatter.png", dpi=90)
            plt.close(fig)
            files.append("scatter.png")
    return files
