"""PNG plots of a run: an overview of every recorded signal and the scenario's own plots, drawn in
display units (km, deg, km/s, g, W/cm2, kJ/cm2: `display_units`) whose labels say the unit shown,
while timeseries.csv, timeseries.parquet and summary.json keep SI."""

import math

import matplotlib

from aotv_cosim.output.display_units import display

matplotlib.use("Agg")
import matplotlib.pyplot as plt

PANELS = 12
"""Panels per overview page."""


def _shown(system, signal) -> tuple:
    """(label suffix ' [unit]' in the unit drawn, factor from SI) of a recorded signal: a Real one
    in its display unit, an Integer, Boolean or Enumeration one as it is."""
    variable = system.variable(signal)
    unit = variable.unit or ""
    shown, factor = display(signal, unit) if variable.type == "Real" else (unit, 1.0)
    return (f" [{shown}]" if shown else ""), factor


def overview(out_dir, system, columns, times, rows, title):
    """overview.png (and overview-2.png, ...): each recorded signal against time; an Integer,
    Boolean or Enumeration one as steps (it changes at communication points), no String one."""
    files = []
    drawn = [c for c in columns if system.variable(c).type != "String"]
    for page, first in enumerate(range(0, len(drawn), PANELS)):
        names = drawn[first:first + PANELS]
        ncols = 3 if len(names) > 4 else 2 if len(names) > 1 else 1
        nrows = math.ceil(len(names) / ncols)
        fig, axes = plt.subplots(nrows, ncols, figsize=(4.2 * ncols, 2.6 * nrows), squeeze=False)
        for ax, name in zip(axes.flat, names):
            unit, factor = _shown(system, name)
            ax.plot(times, rows[:, columns.index(name)] * factor, lw=1.2,
                    drawstyle="default" if system.variable(name).type == "Real" else "steps-post")
            ax.set_title(name + unit, fontsize=9)
            ax.set_xlabel("time [s]", fontsize=8)
            ax.tick_params(labelsize=7)
            ax.grid(alpha=0.3)
        for ax in list(axes.flat)[len(names):]:
            ax.axis("off")
        fig.suptitle(title, fontsize=10)
        fig.tight_layout()
        path = out_dir / ("overview.png" if page == 0 else f"overview-{page + 1}.png")
        fig.savefig(path, dpi=90)
        plt.close(fig)
        files.append(path.name)
    return files


def custom(out_dir, system, spec, columns, times, rows):
    """plot_<name>.png: the signals of one scenario plot against time or another signal."""
    x_name = spec.get("x", "time")
    x_unit, x_factor = ("", 1.0) if x_name == "time" else _shown(system, x_name)
    x = times if x_name == "time" else rows[:, columns.index(x_name)] * x_factor
    fig, ax = plt.subplots(figsize=(7, 4))
    for name in spec["signals"]:
        unit, factor = _shown(system, name)
        ax.plot(x, rows[:, columns.index(name)] * factor, lw=1.3, label=name + unit)
    ax.set_xlabel("time [s]" if x_name == "time" else x_name + x_unit)
    ax.set_title(spec.get("title", spec["name"]))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    path = out_dir / f"plot_{spec['name']}.png"
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path.name
