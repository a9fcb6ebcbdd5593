"""Campaign plots a GNC engineer reads: histograms of chosen columns, inputs against outputs, and
the exit-state scatter with its 3-sigma ellipse outlined under the points (histograms of the two
exit values when only one value is dispersed: the ellipse would be degenerate); the sweep and
corridor plots. Runs are coloured by outcome class, one colour per class everywhere; the apogee
error is on a symmetric-log axis around the capture band, other columns on axes clipped to their
far-out fences with the runs beyond marked (`plot_axes`, which says why). Every axis is labelled
with the column and its unit, in display units (km, deg, km/s, W/cm2, kJ/cm2, g:
`output.display_units`) while the files keep SI; ticks are limited in number and never offset."""

import numpy as np

from aotv_cosim.campaigns.plot_axes import (
    OUTCOME_COLORS,
    Scale,
    band_patch,
    classes_of,
    color_of,
    histogram_by_outcome,
    scatter_by_outcome,
)
from aotv_cosim.campaigns.statistics import ellipse_3sigma
from aotv_cosim.output.display_units import display
from aotv_cosim.status import Status


def label(name, units) -> str:
    """Axis label: the column and its unit ('1' for dimensionless)."""
    unit = units.get(name, "")
    return f"{name} [{unit}]" if unit else name


def shown_label(name, units) -> str:
    """Axis label in display units (`display`): the column and the unit its values are drawn in."""
    shown = display(name, units.get(name, ""))[0]
    return f"{name} [{shown}]" if shown else name


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
    ok = [r for r in rows if r["status"] == Status.COMPLETED]
    x = np.array([float(r[x_name]) for r in ok])
    y = np.array([float(r[y_name]) for r in ok])
    keep = np.isfinite(x) & np.isfinite(y)
    return x[keep], y[keep]


def _drawn_values(rows, name):
    """(values, classes) of a histogram's column: a dispersed input over every run (its class says
    where the draw led), any other column over the completed runs, finite values only."""
    every = name.startswith("dispersed.")
    pairs = [(float(r[name]), c) for r, c in zip(rows, classes_of(rows))
             if every or r["status"] == Status.COMPLETED]
    pairs = [(v, c) for v, c in pairs if np.isfinite(v)]
    return np.array([v for v, _ in pairs], dtype=float), [c for _, c in pairs]


def plots(out_dir, rows, scenario, units, columns, versus) -> tuple:
    """Write histograms.png (columns), versus.png ((input, output) pairs) and scatter.png (the
    scenario's exit-state pair); returns (file names, notes on columns that could not be drawn).
    Runs are coloured by outcome class when the scenario classifies them, the apogee error is drawn
    on a symmetric-log axis around the capture band and other columns on axes clipped to their
    far-out fences, the runs beyond marked (`plot_axes`)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    band = scenario.outcome.band if scenario.outcome is not None else None
    files, notes, drawn = [], [], []
    for name in columns:
        x, classes = _drawn_values(rows, name)
        if len(x) < 2:
            notes.append(f"`{name}`: fewer than 2 finite values, no histogram")
        elif np.ptp(x) == 0.0:
            notes.append(f"`{name}`: constant {x[0]:.6g} {units.get(name, '')} over the runs, no histogram")
        else:
            drawn.append((name, x, classes))
    if drawn:
        fig, axes = _grid(plt, len(drawn))
        legend = {}
        for ax, (name, x, classes) in zip(axes, drawn):
            factor = display(name, units.get(name, ""))[1]
            scale = Scale(name, x * factor, band * display(name, "m")[1] if band else None)
            handles = histogram_by_outcome(ax, x * factor, classes, scale, count=min(30, max(5, len(x) // 5)))
            legend.update({k: v for k, v in handles.items() if k in _CLASS_NAMES})
            _panel_legend(ax, scale, band, name, {k: v for k, v in handles.items() if k not in _CLASS_NAMES}, "x")
            ax.set_xlabel(shown_label(name, units) + (" (symlog)" if scale.symlog else ""), fontsize=8)
            ax.set_ylabel("runs", fontsize=8)
            if len(x) < len(rows):
                ax.set_title(f"{len(x)} of {len(rows)} runs have a value", fontsize=7)
            _style(ax, scale, "x")
        files.append(_save_with_legend(fig, out_dir, "histograms.png", legend))
    pairs = [(a, b) for a, b in versus if any(np.isfinite(float(r[a])) for r in rows)]
    if pairs:
        fig, axes = _grid(plt, len(pairs))
        legend = {}
        classes = classes_of(rows)
        for ax, (a, b) in zip(axes, pairs):
            fx, fy = display(a, units.get(a, ""))[1], display(b, units.get(b, ""))[1]
            x = np.array([float(r[a]) for r in rows]) * fx
            y = np.array([float(r[b]) if r["status"] == Status.COMPLETED else np.nan for r in rows]) * fy
            scale = Scale(b, y[np.isfinite(y)], band * display(b, "m")[1] if band else None)
            handles = scatter_by_outcome(ax, x, y, classes, scale)
            legend.update({k: v for k, v in handles.items() if k in _CLASS_NAMES})
            _panel_legend(ax, scale, band, b, {k: v for k, v in handles.items() if k not in _CLASS_NAMES}, "y")
            ax.set_xlabel(shown_label(a, units), fontsize=8)
            ax.set_ylabel(shown_label(b, units) + (" (symlog)" if scale.symlog else ""), fontsize=8)
            _style(ax, scale, "y")
        files.append(_save_with_legend(fig, out_dir, "versus.png", legend))
    if len(scenario.scatter) == 2:
        at = "exit" if scenario.stop_conditions else "final"
        a, b = (f"{at}.{s}" for s in scenario.scatter)
        x, y = _pairs(rows, a, b)
        if len(x) > 2 and len(scenario.dispersions) < 2:
            files.append(_exit_histograms(plt, out_dir, (a, x), (b, y), units))
        elif len(x) > 2:
            files.append(_exit_scatter(plt, out_dir, rows, a, b, units))
    return files, notes


_CLASS_NAMES = {"captured", "skip out", "undershoot", "impact", "failed", "run"}
"""The legend labels of the outcome classes (`plot_axes._name`), shown once per figure."""


def _panel_legend(ax, scale, band, name, handles, axis) -> None:
    """A panel's own legend: the capture band on the apogee error's `axis`, the runs beyond the axis."""
    if scale.symlog and band:
        shown, factor = display(name, "m")
        label = f"capture band +-{band * factor:g} {shown}"
        handles = {label: band_patch(ax, band * factor, axis, label), **handles}
    if handles:
        ax.legend(handles=list(handles.values()), labels=list(handles), fontsize=6, loc="best")


def _style(ax, scale, axis) -> None:
    """`axes_style`, but a symlog `axis` keeps its own decade ticks."""
    if not scale.symlog:
        axes_style(ax)
        return
    from matplotlib.ticker import MaxNLocator, ScalarFormatter

    other = ax.yaxis if axis == "x" else ax.xaxis
    other.set_major_locator(MaxNLocator(nbins=4))
    formatter = ScalarFormatter(useOffset=False)
    formatter.set_powerlimits((-3, 5))
    other.set_major_formatter(formatter)
    ax.tick_params(labelsize=8)
    ax.grid(alpha=0.3)


def _save_with_legend(fig, out_dir, name, legend) -> str:
    """Save `fig` with the outcome classes drawn (`legend`, {label: handle}) above its panels, in
    the classes' order."""
    import matplotlib.pyplot as plt

    order = [name.replace("_", " ") for name in OUTCOME_COLORS]
    legend = dict(sorted(legend.items(), key=lambda item: order.index(item[0]) if item[0] in order else len(order)))
    if legend:
        fig.legend(handles=list(legend.values()), labels=list(legend), loc="upper center", ncol=len(legend),
                   fontsize=8, title="outcome", title_fontsize=8, frameon=False)
        fig.tight_layout(rect=(0, 0, 1, 0.93))
    else:
        fig.tight_layout()
    fig.savefig(out_dir / name, dpi=90)
    plt.close(fig)
    return name


def _exit_scatter(plt, out_dir, rows, a, b, units) -> str:
    """scatter.png: the exit-state pair of the completed runs, coloured by outcome class, over the
    3-sigma ellipse of all of them."""
    done = [r for r in rows if r["status"] == Status.COMPLETED and np.isfinite(float(r[a]))
            and np.isfinite(float(r[b]))]
    x, y = np.array([float(r[a]) for r in done]), np.array([float(r[b]) for r in done])
    classes = np.array(classes_of(done), dtype=object)
    fig, ax = plt.subplots(figsize=(5.5, 4.5))
    fx, fy = display(a, units.get(a, ""))[1], display(b, units.get(b, ""))[1]
    ex, ey = ellipse_3sigma(x, y)
    ax.plot(ex * fx, ey * fy, "r-", lw=1.2, zorder=1, label="3-sigma ellipse")
    for cls in dict.fromkeys(classes):
        pick = classes == cls
        name = cls.replace("_", " ") if isinstance(cls, str) else "run"
        ax.plot(x[pick] * fx, y[pick] * fy, ".", ms=3, alpha=0.7, zorder=2, color=color_of(cls),
                label=f"{name} ({pick.sum()})")
    ax.set_xlabel(shown_label(a, units), fontsize=9)
    ax.set_ylabel(shown_label(b, units), fontsize=9)
    axes_style(ax)
    ax.legend(fontsize=7)
    return _save(fig, out_dir, "scatter.png")


def _exit_histograms(plt, out_dir, first, second, units) -> str:
    """scatter.png for a campaign with one dispersed value: the exit pair then lies on a curve,
    whose 3-sigma ellipse would be degenerate, so each value gets a histogram with its 0.135 and
    99.865 percentiles marked."""
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.6))
    for ax, (name, x) in zip(axes, (first, second)):
        factor = display(name, units.get(name, ""))[1]
        ax.hist(x * factor, bins=min(30, max(5, len(x) // 5)), color="tab:blue", alpha=0.8)
        for p in (0.135, 99.865):
            ax.axvline(np.percentile(x, p) * factor, color="tab:red", lw=1, ls="--")
        ax.set_xlabel(shown_label(name, units), fontsize=8)
        ax.set_ylabel("runs", fontsize=8)
        axes_style(ax)
    axes[0].set_title("one dispersed value: histograms (dashed: 0.135 / 99.865 percentiles)", fontsize=8,
                      loc="left")
    return _save(fig, out_dir, "scatter.png")


def sweep_plot(out_dir, rows, parameters, units, outcome_settings) -> str:
    """sweep.png: for one swept parameter, the outcome metrics and extrema against it (one panel
    each, display units, points coloured by outcome class, the capture band drawn on the apogee
    error); for two or more, the class of every point over the first two parameters."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    classes = [r.get("outcome", r["status"]) for r in rows]
    colors = [color_of(c) for c in classes]
    if len(parameters) >= 2:
        a, b = parameters[:2]
        fig, ax = plt.subplots(figsize=(6, 4.8))
        for cls in dict.fromkeys(classes):
            pick = [r for r, c in zip(rows, classes) if c == cls]
            ax.scatter([r[a] for r in pick], [r[b] for r in pick], s=30, label=cls,
                       color=color_of(cls))
        ax.set_xlabel(label(a, units), fontsize=9)
        ax.set_ylabel(label(b, units), fontsize=9)
        ax.legend(fontsize=8)
        axes_style(ax)
        return _save(fig, out_dir, "sweep.png")
    x_name = parameters[0]
    panels = [n for n in ("outcome.apogee_error", "outcome.dv_total", "min.vehicle.h", "max.vehicle.qdot",
                          "max.vehicle.load_factor", "outcome.heat_load") if n in units]
    panels = panels or [n for n in units if n.startswith(("min.", "max."))][:4]
    fig, axes = _grid(plt, len(panels))
    x = np.array([float(r[x_name]) for r in rows])
    for ax, name in zip(axes, panels):
        shown, factor = display(name, units.get(name, ""))
        y = np.array([float(r[name]) for r in rows]) * factor
        finite = np.isfinite(y)
        ax.plot(x[finite], y[finite], "-", color="0.7", lw=1, zorder=1)
        ax.scatter(x[finite], y[finite], c=[c for c, f in zip(colors, finite) if f], s=22, zorder=2)
        if name == "outcome.apogee_error" and outcome_settings is not None:
            band = outcome_settings.band * factor
            ax.axhspan(-band, band, color="tab:green", alpha=0.15, zorder=0, label="capture band")
            ax.legend(fontsize=7)
        ax.set_xlabel(label(x_name, units), fontsize=8)
        ax.set_ylabel(f"{name} [{shown}]", fontsize=8)
        axes_style(ax)
    handles = [plt.Line2D([], [], marker="o", ls="", color=color_of(c), label=c)
               for c in dict.fromkeys(classes)]
    fig.legend(handles=handles, loc="upper right", fontsize=7, ncol=len(handles))
    fig.tight_layout(rect=(0, 0, 1, 0.94))
    fig.savefig(out_dir / "sweep.png", dpi=90)
    plt.close(fig)
    return "sweep.png"


def corridor_plot(out_dir, result) -> str:
    """corridor.png: apogee error (km) against the entry flight-path angle (deg) of the runs flown
    at full lift up and full lift down, on an axis clipped to +-8 capture bands around the aim
    (runs beyond it, and those that never exit or leave on an unbound orbit, drawn as triangles on
    the axis's edge), the capture band, each bound dashed, the corridor shaded, its width in the
    title."""
    import math

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.6))
    band = result["band_m"] / 1e3
    limit = 8 * band
    ax.axhspan(-band, band, color="tab:green", alpha=0.15, label=f"capture band +-{band:g} km")
    own = result["plant"] == "bank"
    for bound, name, sigma, color in (("steep", "full lift up", 0, "tab:blue"),
                                      ("shallow", "full lift down", 180, "tab:red")):
        points = sorted((math.degrees(g), float(e) / 1e3) for g, e in result[bound]["points"])
        how = f"sigma = {sigma} deg" + (f", L/D {result['lift_to_drag']:.3g} of the vehicle"
                                         if result["lift_to_drag"] is not None else "") if own else \
            f"L/D = {result['lift_to_drag']:g}"
        clipped_line(ax, [g for g, _ in points], [e for _, e in points], limit, color, f"{name} ({how})")
        ax.axvline(math.degrees(result[bound]["gamma0"]), color=color, ls="--", lw=1)
    ax.axvspan(math.degrees(result["steep"]["gamma0"]), math.degrees(result["shallow"]["gamma0"]),
               color="0.85", zorder=0, label="corridor")
    ax.axvline(math.degrees(result["nominal_gamma0"]), color="black", lw=1, label="nominal entry")
    ax.set_ylim(-1.08 * limit, 1.08 * limit)
    ax.set_xlabel("entry flight-path angle gamma0 [deg]", fontsize=9)
    ax.set_ylabel(f"exit apogee error [km] (clipped at +-{limit:g})", fontsize=9)
    aim = "the target apogee" if result["aim"] == "target" else "the band's edges"
    ax.set_title(f"corridor {math.degrees(result['steep']['gamma0']):.4f} ... "
                 f"{math.degrees(result['shallow']['gamma0']):.4f} deg, width {result['width_deg']:.4f} deg "
                 f"(exits on {aim}, to {math.degrees(result['angle_tolerance_rad']):.1e} deg)", fontsize=8)
    axes_style(ax)
    ax.legend(fontsize=7, loc="best")
    return _save(fig, out_dir, "corridor.png")


def clipped_line(ax, x, y, limit, color, label) -> None:
    """y (display units) against x as a line through its points, every value beyond +-limit (an
    infinite one too) drawn as a triangle on that edge pointing away: the axis is clipped, not
    the data."""
    import numpy as np

    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    shown = np.clip(np.nan_to_num(y, nan=-np.inf), -limit, limit)
    ax.plot(x, shown, "-", lw=1, color=color, label=label)
    inside = np.abs(shown) < limit
    ax.plot(x[inside], shown[inside], "o", ms=3, color=color)
    for sign, marker in ((1, "^"), (-1, "v")):
        edge = shown == sign * limit
        ax.plot(x[edge], shown[edge], marker, ms=5, color=color, mfc="none", clip_on=False)


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
