"""Campaign plots a GNC engineer reads: histograms of chosen columns, inputs against outputs, and
the exit-state scatter with its 3-sigma ellipse outlined under the points (histograms of the two
exit values when only one value is dispersed: the ellipse would be degenerate); the sweep and
corridor plots. Every axis is labelled
with the column and its unit, in display units (km, km/s, W/cm2, kJ/cm2, g: `units.display`) while the
files keep SI; ticks are limited in number and never offset."""

import numpy as np

from aotv_cosim.campaigns.statistics import completed_values, ellipse_3sigma
from aotv_cosim.campaigns.units import display
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


def plots(out_dir, rows, scenario, units, columns, versus) -> tuple:
    """Write histograms.png (columns), versus.png ((input, output) pairs) and scatter.png (the
    scenario's exit-state pair); returns (file names, notes on columns that could not be drawn)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    files, notes, drawn = [], [], []
    for name in columns:
        x = completed_values(rows, name)
        if len(x) < 2:
            notes.append(f"`{name}`: fewer than 2 finite values, no histogram")
        elif np.ptp(x) == 0.0:
            notes.append(f"`{name}`: constant {x[0]:.6g} {units.get(name, '')} over the runs, no histogram")
        else:
            drawn.append((name, x))
    if drawn:
        fig, axes = _grid(plt, len(drawn))
        for ax, (name, x) in zip(axes, drawn):
            ax.hist(x * display(name, units.get(name, ""))[1], bins=min(30, max(5, len(x) // 5)),
                    color="tab:blue", alpha=0.8)
            ax.set_xlabel(shown_label(name, units), fontsize=8)
            ax.set_ylabel("runs", fontsize=8)
            axes_style(ax)
        files.append(_save(fig, out_dir, "histograms.png"))
    pairs = [(a, b, *_pairs(rows, a, b)) for a, b in versus]
    pairs = [p for p in pairs if len(p[2]) > 1]
    if pairs:
        fig, axes = _grid(plt, len(pairs))
        for ax, (a, b, x, y) in zip(axes, pairs):
            ax.plot(x * display(a, units.get(a, ""))[1], y * display(b, units.get(b, ""))[1], ".", ms=3, alpha=0.7)
            ax.set_xlabel(shown_label(a, units), fontsize=8)
            ax.set_ylabel(shown_label(b, units), fontsize=8)
            axes_style(ax)
        files.append(_save(fig, out_dir, "versus.png"))
    if len(scenario.scatter) == 2:
        at = "exit" if scenario.stop_conditions else "final"
        a, b = (f"{at}.{s}" for s in scenario.scatter)
        x, y = _pairs(rows, a, b)
        if len(x) > 2 and len(scenario.dispersions) < 2:
            files.append(_exit_histograms(plt, out_dir, (a, x), (b, y), units))
        elif len(x) > 2:
            fig, ax = plt.subplots(figsize=(5.5, 4.5))
            fx, fy = display(a, units.get(a, ""))[1], display(b, units.get(b, ""))[1]
            ex, ey = ellipse_3sigma(x, y)
            ax.plot(ex * fx, ey * fy, "r-", lw=1.2, zorder=1, label="3-sigma ellipse")
            ax.plot(x * fx, y * fy, ".", ms=3, alpha=0.7, zorder=2, label=f"{len(x)} runs")
            ax.set_xlabel(shown_label(a, units), fontsize=9)
            ax.set_ylabel(shown_label(b, units), fontsize=9)
            axes_style(ax)
            ax.legend(fontsize=8)
            files.append(_save(fig, out_dir, "scatter.png"))
    return files, notes


OUTCOME_COLORS = {"captured": "tab:green", "skip_out": "tab:orange", "undershoot": "tab:blue",
                  "impact": "black", "failed": "tab:red"}
"""Marker colour of each outcome class."""


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
    colors = [OUTCOME_COLORS.get(c, "tab:gray") for c in classes]
    if len(parameters) >= 2:
        a, b = parameters[:2]
        fig, ax = plt.subplots(figsize=(6, 4.8))
        for cls in dict.fromkeys(classes):
            pick = [r for r, c in zip(rows, classes) if c == cls]
            ax.scatter([r[a] for r in pick], [r[b] for r in pick], s=30, label=cls,
                       color=OUTCOME_COLORS.get(cls, "tab:gray"))
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
    handles = [plt.Line2D([], [], marker="o", ls="", color=OUTCOME_COLORS.get(c, "tab:gray"), label=c)
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
