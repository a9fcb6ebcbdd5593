"""The benchmark's scorecard as text (console, report.md) and its plot: the laws side by side."""

import math

import numpy as np

from aotv_cosim.campaigns.figures import axes_style
from aotv_cosim.campaigns.statistics import completed_values

PANELS = (("outcome.apogee_error", "apogee error", "m"), ("outcome.dv_total", "correction dv", "m/s"),
          ("outcome.peak_heat_rate", "peak heat rate", "W/m2"), ("outcome.heat_load", "heat load", "J/m2"),
          ("outcome.peak_load_factor", "peak load factor", "1"), ("outcome.int_abs_u", "int |u| dt", "m/s"))
"""(row column, name, SI unit) of each panel of benchmark.png."""


def _cell(v) -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        return "-" if not math.isfinite(v) else f"{v:.4g}"
    return str(v)


def table(cards, units) -> list:
    """Rows of text cells: a header with units, then one row per law."""
    head = [f"{c} [{u}]" if u and u != "1" else c for c, u in units.items()]
    return [head] + [[_cell(card[c]) for c in units] for card in cards]


def console(cards, units) -> str:
    """The scorecard transposed (one column per law, one line per figure), for a terminal, in
    display units (km, W/cm2, kJ/cm2, g; `units.display`); the files keep SI."""
    from aotv_cosim.output.display_units import display

    shown, scaled = {}, []
    for column, unit in units.items():
        shown[column], _ = display(column, unit)
    for card in cards:
        scaled.append({c: v * display(c, units[c])[1] if isinstance(v, float) else v for c, v in card.items()})
    rows = table(scaled, shown)
    lines = list(zip(*rows))
    widths = [max(len(c) for c in col) for col in zip(*lines)]
    return "\n".join("  ".join(c.ljust(w) if k == 0 else c.rjust(w) for k, (c, w) in enumerate(zip(line, widths)))
                     for line in lines)


def markdown(result, cards, units) -> str:
    rows = table(cards, units)
    lines = list(zip(*rows))  # one line per figure, one column per law
    out = [f"# Guidance benchmark: {result['set']}", "",
           f"{result['runs']} runs per law, campaign seed {result['seed']}: run k of every law flies the same "
           "dispersed values. Percentiles over the completed runs with a finite value; p0.135 / p99.865 "
           "bound the 3-sigma-equivalent band. A `-` is a figure the runs do not provide.", "",
           "| " + " | ".join(lines[0]) + " |", "|---|" + "---:|" * (len(lines[0]) - 1)]
    out += ["| " + " | ".join(line) + " |" for line in lines[1:]]
    out += ["", f"Campaign wall time of the laws flown now: {result['wall_time_s']:.1f} s.", ""]
    out += [f"- {law}: rows reused from an earlier campaign with the same scenario, FMUs, dispersions, seed "
            "and N" if info.get("reused") else f"- {law}: [{law}/report.md]({law}/report.md)"
            for law, info in result["laws"].items()]
    out += [""] + [f"![{p}]({p})" for p in result.get("plots", [])]
    return "\n".join(out) + "\n"


def plots(out_dir, rows_by_law, band=None, panels=PANELS) -> list:
    """benchmark.png: the outcome classes of each law (stacked bars, the campaign plots' colours),
    then one panel per metric of `panels` (`PANELS`), the laws side by side as box plots (median, quartiles,
    whiskers at the 0.135 / 99.865 percentiles, runs beyond them as points) over the completed runs
    with a finite value, in display units (km, W/cm2, kJ/cm2, g); the apogee error on a
    symmetric-log axis (linear within +-1 km) with the capture band (+-band m) shaded; every other
    metric on an axis clipped to the laws' far-out fences when runs lie beyond them (`plot_axes`
    says why), those runs drawn as triangles on its edge and counted in the legend. The capture rate is under each law's name; the last cell holds the
    outcome classes' legend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from aotv_cosim.output.display_units import display

    laws = list(rows_by_law)
    ticks = [f"{law}\n{_capture_rate(rows_by_law[law]):.0f} % capt." for law in laws]
    ncols = max(4, -(-(len(panels) + 2) // 2))  # the outcomes, the panels and the legend, in two rows
    fig, axes = plt.subplots(2, ncols, figsize=(max(4.0 * ncols, 4 * (1.2 + 0.5 * len(laws))), 8))
    _outcome_panel(axes.flat[0], rows_by_law, laws)
    for ax, (column, name, unit) in zip(list(axes.flat)[1:], panels):
        shown, factor = display(column, unit)
        data = [completed_values(rows_by_law[law], column) * factor for law in laws]
        if not any(len(x) for x in data):
            ax.set_title(f"{name}: no finite value", fontsize=9)
            ax.axis("off")
            continue
        ax.boxplot([x if len(x) else [np.nan] for x in data], whis=(0.135, 99.865), widths=0.6,
                   flierprops={"markersize": 2, "alpha": 0.5}, medianprops={"color": "tab:red"})
        if column == "outcome.apogee_error":
            ax.set_yscale("symlog", linthresh=1.0)
            if band:
                ax.axhspan(-band * factor, band * factor, color="tab:green", alpha=0.2, zorder=0,
                           label=f"capture band +-{band * factor:g} {shown}")
                ax.legend(fontsize=7, loc="upper left")
        else:
            axes_style(ax)
            _clip_to_fences(ax, data)
        ax.grid(alpha=0.3, axis="y")
        ax.set_xticks(range(1, len(laws) + 1), ticks, fontsize=7, rotation=30, ha="right")
        ax.set_ylabel(f"{name} [{shown}]", fontsize=8)
        ax.tick_params(axis="y", labelsize=8)
    for ax in list(axes.flat)[len(panels) + 1:]:
        ax.axis("off")
    handles, labels = axes.flat[0].get_legend_handles_labels()
    axes.flat[-1].legend(handles, labels, title="outcome (first panel)", loc="center", fontsize=9)
    fig.tight_layout()
    fig.savefig(out_dir / "benchmark.png", dpi=90)
    plt.close(fig)
    return ["benchmark.png"]


def _outcome_panel(ax, rows_by_law, laws) -> None:
    """The share of each outcome class per law, stacked bars in the classes' colours."""
    from aotv_cosim.campaigns.plot_axes import OUTCOME_COLORS

    bottom = np.zeros(len(laws))
    for cls, color in OUTCOME_COLORS.items():
        share = np.array([100.0 * sum(r["outcome"] == cls for r in rows_by_law[law]) / max(1, len(rows_by_law[law]))
                          for law in laws])
        ax.bar(range(1, len(laws) + 1), share, bottom=bottom, color=color, width=0.6, label=cls.replace("_", " "))
        bottom += share
    ax.set_xticks(range(1, len(laws) + 1), laws, fontsize=7, rotation=30, ha="right")
    ax.set_ylim(0, 100)
    ax.set_ylabel("runs [%]", fontsize=8)
    ax.set_title("outcome", fontsize=9)
    ax.tick_params(axis="y", labelsize=8)


def _clip_to_fences(ax, data) -> None:
    """Clip the y axis to the laws' far-out fences (`plot_axes.fences` of each law, the widest
    over the laws) when runs lie beyond; those runs drawn as triangles on the edge, their number
    in the legend. (The whiskers cannot bound it: two skip-outs in 1000 runs put the 99.865th
    percentile between them.)"""
    from aotv_cosim.campaigns.plot_axes import fences

    finite = [x for x in data if len(x)]
    limits = [fences(x) for x in finite]
    low, high = min(f[0] for f in limits), max(f[1] for f in limits)
    lowest, highest = min(x.min() for x in finite), max(x.max() for x in finite)
    if high <= low or (low <= lowest and high >= highest):
        return
    below = sum(int((x < low).sum()) for x in finite)
    above = sum(int((x > high).sum()) for x in finite)
    pad = 0.06 * (high - low)
    ax.set_ylim(low - pad, high + pad)
    labels = []
    for k, x in enumerate(data, start=1):
        for mask, edge, marker in ((x < low, low - pad, "v"), (x > high, high + pad, "^")):
            if mask.any():
                ax.plot([k] * int(mask.sum()), [edge] * int(mask.sum()), marker, ms=4, mfc="none", color="0.3",
                        clip_on=False)
    if below:
        labels.append(f"{below} runs below the axis (to {lowest:.4g})")
    if above:
        labels.append(f"{above} runs above the axis (to {highest:.4g})")
    ax.legend(handles=[ax.plot([], [], "^" if "above" in t else "v", mfc="none", color="0.3")[0] for t in labels],
              labels=labels, fontsize=6, loc="best")


def _capture_rate(rows) -> float:
    return 100.0 * sum(r["outcome"] == "captured" for r in rows) / len(rows) if rows else math.nan
