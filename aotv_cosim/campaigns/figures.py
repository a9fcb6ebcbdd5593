"""Campaign plots a GNC engineer reads: histograms of chosen columns, inputs against outputs, and
the exit-state scatter with its 3-sigma ellipse drawn under the points. Every axis is labelled
with the column and its SI unit; ticks are limited in number and never offset."""

import numpy as np

from aotv_cosim.campaigns.report import ellipse_3sigma
from aotv_cosim.campaigns.report_tables import values


def label(name, units) -> str:
    """Axis label: the column and its unit ('1' for dimensionless)."""
    unit = units.get(name, "")
    return f"{name} [{unit}]" if unit else name


def axes_style(ax):
    from matplotlib.ticker import MaxNLocator, ScalarFormatter

    for axis in (ax.xaxis, ax.yaxis):
        axis.set_major_locator(MaxNLocator(nbins=4))
        formatter = ScalarFormatter(useOffset=False)
        formatter.set_powerlimits((-3, 5))
        axis.set_major_formatter(formatter)
    ax.tick_params(labelsize=8)
    ax.grid(alpha=0.3)


def _pairs(rows, x_name, y_name):
    ok = [r for r in rows if r["status"] == "completed"]
    x = np.array([float(r[x_name]) for r in ok])
    y = np.array([float(r[y_name]) for r in ok])
    keep = np.isfinite(x) & np.isfinite(y)
    return x[keep], y[keep]


def plots(out_dir, rows, scenario, units, columns, versus) -> tuple:
    """Write histograms.png (columns), versus.png ((input, output) pairs) and scatter.png (the
    scenario's exit-state pair); returns (file names, notes on columns that could not be drawn)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    files, notes, drawn = [], [], []
    for name in columns:
        x = values(rows, name)
        if len(x) < 2:
            notes.append(f"`{name}`: fewer than 2 finite values, no histogram")
        elif np.ptp(x) == 0.0:
            notes.append(f"`{name}`: constant {x[0]:.6g} {units.get(name, '')} over the runs, no histogram")
        else:
            drawn.append((name, x))
    if drawn:
        fig, axes = _grid(plt, len(drawn))
        for ax, (name, x) in zip(axes, drawn):
            ax.hist(x, bins=min(30, max(5, len(x) // 5)), color="tab:blue", alpha=0.8)
            ax.set_xlabel(label(name, units), fontsize=8)
            ax.set_ylabel("runs", fontsize=8)
            axes_style(ax)
        files.append(_save(fig, out_dir, "histograms.png"))
    pairs = [(a, b, *_pairs(rows, a, b)) for a, b in versus]
    pairs = [p for p in pairs if len(p[2]) > 1]
    if pairs:
        fig, axes = _grid(plt, len(pairs))
        for ax, (a, b, x, y) in zip(axes, pairs):
            ax.plot(x, y, ".", ms=3, alpha=0.7)
            ax.set_xlabel(label(a, units), fontsize=8)
            ax.set_ylabel(label(b, units), fontsize=8)
            axes_style(ax)
        files.append(_save(fig, out_dir, "versus.png"))
    if len(scenario.scatter) == 2:
        at = "exit" if scenario.stop_conditions else "final"
        a, b = (f"{at}.{s}" for s in scenario.scatter)
        x, y = _pairs(rows, a, b)
        if len(x) > 2:
            fig, ax = plt.subplots(figsize=(5.5, 4.5))
            ax.plot(*ellipse_3sigma(x, y), "r-", lw=1.2, zorder=1, label="3-sigma ellipse")
            ax.plot(x, y, ".", ms=3, alpha=0.7, zorder=2, label=f"{len(x)} runs")
            ax.set_xlabel(label(a, units), fontsize=9)
            ax.set_ylabel(label(b, units), fontsize=9)
            axes_style(ax)
            ax.legend(fontsize=8)
            files.append(_save(fig, out_dir, "scatter.png"))
    return files, notes


def _grid(plt, n):
    ncols = min(3, n)
    nrows = -(-n // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.4 * ncols, 3.2 * nrows), squeeze=False)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    return fig, list(axes.flat)[:n]


def _save(fig, out_dir, name):
    import matplotlib.pyplot as plt

    fig.tight_layout()
    fig.savefig(out_dir / name, dpi=90)
    plt.close(fig)
    return name
