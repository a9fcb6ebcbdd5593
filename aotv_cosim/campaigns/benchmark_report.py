"""The benchmark's scorecard as text (console, report.md) and its plots: the laws side by side
(benchmark.png) and, in a set with an oracle, each law's dv penalty against it run by run
(penalty.png)."""

import math

import numpy as np

from aotv_cosim.campaigns import oracle_score
from aotv_cosim.campaigns.figures import axes_style
from aotv_cosim.campaigns.statistics import completed_values

PANELS = (("outcome.apogee_error", "apogee error", "m"), ("outcome.dv_total", "correction dv", "m/s"),
          ("outcome.peak_heat_rate_total", "peak total heat rate", "W/m2"),
          ("outcome.heat_load_total", "total heat load", "J/m2"),
          ("outcome.peak_load_factor", "peak load factor", "1"), ("outcome.int_abs_u", "int |u| dt", "m/s"))
"""(row column, name, SI unit) of each panel of benchmark.png. The heating is the total,
convective plus radiative, which the stated heat-rate limit is on (`limits`)."""
CONVECTIVE = {"outcome.peak_heat_rate_total": ("outcome.peak_heat_rate", "peak heat rate", "W/m2"),
              "outcome.heat_load_total": ("outcome.heat_load", "heat load", "J/m2")}
"""The convective panel drawn instead of a total one in a set whose runs give no total (its vehicle
has no radiative heating, or the set does not record it: benchmark_seed000)."""
PENALTY_PANEL = (oracle_score.PENALTY, "dv penalty vs the oracle", "m/s")
"""The panel of the dv penalty against the set's oracle, after the correction dv's."""


def _cell(v) -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        return "-" if not math.isfinite(v) else f"{v:.4g}"
    return str(v)


def panels_of(rows_by_law, oracle=None) -> tuple:
    """`PANELS` for these rows ({law: rows}): a total heating panel where no run gives a finite
    total is the convective one (`CONVECTIVE`); with an `oracle` (its law name) the dv penalty's
    panel follows the correction dv's."""
    def given(column):
        return any(len(completed_values(rows, column)) for rows in rows_by_law.values())

    panels = [p if p[0] not in CONVECTIVE or given(p[0]) else CONVECTIVE[p[0]] for p in PANELS]
    if oracle is not None:
        at = next(k + 1 for k, p in enumerate(panels) if p[0] == "outcome.dv_total")
        panels.insert(at, PENALTY_PANEL)
    return tuple(panels)


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
    text = ["  ".join(c.ljust(w) if k == 0 else c.rjust(w) for k, (c, w) in enumerate(zip(line, widths)))
            for line in lines]
    return "\n".join([*text, _oracle_note(cards, "\n")] if oracle_score.ROLE in units else text)


def _oracle_note(cards, sep) -> str:
    """What the oracle's row and the dv_penalty lines are (`oracle_score`), for the console and report.md."""
    oracle = next(card for card in cards if card[oracle_score.ROLE] == oracle_score.ORACLE)
    bound = (f"{oracle['law']} is the set's oracle, the bound, not a competitor: the best pass each run allows "
             f"with perfect knowledge of that run; it captured {oracle['captured']} of {oracle['runs']} runs.")
    penalty = ("dv_penalty: a law's correction dv minus the oracle's in the same run, over the runs both captured "
               "(a run the law did not capture has no penalty: it counts in its capture rate); the oracle's row "
               "has none.")
    return sep.join([bound, penalty])


def markdown(result, cards, units) -> str:
    rows = table(cards, units)
    lines = list(zip(*rows))  # one line per figure, one column per law
    out = [f"# Guidance benchmark: {result['set']}", "",
           f"{result['runs']} runs per law, campaign seed {result['seed']}: run k of every law flies the same "
           "dispersed values. Percentiles over the completed runs with a finite value; p0.135 / p99.865 "
           "bound the 3-sigma-equivalent band. A `-` is a figure the runs do not provide.", "",
           "| " + " | ".join(lines[0]) + " |", "|---|" + "---:|" * (len(lines[0]) - 1)]
    out += ["| " + " | ".join(line) + " |" for line in lines[1:]]
    if oracle_score.ROLE in units:
        out += ["", _oracle_note(cards, "\n\n")]
    out += ["", f"Campaign wall time of the laws flown now: {result['wall_time_s']:.1f} s.", ""]
    out += [f"- {law}: rows reused from an earlier campaign with the same scenario, FMUs, dispersions, seed "
            "and N" if info.get("reused") else f"- {law}: [{law}/report.md]({law}/report.md)"
            for law, info in result["laws"].items()]
    out += [""] + [f"![{p}]({p})" for p in result.get("plots", [])]
    return "\n".join(out) + "\n"


def plots(out_dir, rows_by_law, band=None, panels=PANELS, oracle=None) -> list:
    """benchmark.png: the outcome classes of each law (stacked bars, the campaign plots' colours),
    then one panel per metric of `panels` (`PANELS`, `panels_of`), the laws side by side as box plots (median,
    quartiles, whiskers at the 0.135 / 99.865 percentiles, runs beyond them as points) over the completed runs
    with a finite value, in display units (km, W/cm2, kJ/cm2, g); the apogee error on a
    symmetric-log axis (linear within +-1 km) with the capture band (+-band m) shaded; every other
    metric on an axis clipped to the laws' far-out fences when runs lie beyond them (`plot_axes`
    says why), those runs drawn as triangles on its edge and counted in the legend. The capture rate is under each law's
    name (the set's `oracle`, if named, marked as the bound); the last cell holds the outcome classes' legend."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from aotv_cosim.output.display_units import display

    laws = list(rows_by_law)
    names = [_shown(law, oracle) for law in laws]
    ticks = [f"{name}\n{_capture_rate(rows_by_law[law]):.0f} % capt." for law, name in zip(laws, names)]
    ncols = max(4, -(-(len(panels) + 2) // 2))  # the outcomes, the panels and the legend, in two rows
    fig, axes = plt.subplots(2, ncols, figsize=(max(4.0 * ncols, 4 * (1.2 + 0.5 * len(laws))), 8))
    _outcome_panel(axes.flat[0], rows_by_law, laws, names)
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


def penalty_plot(out_dir, rows_by_law, oracle) -> str:
    """penalty.png: one panel per law (not the `oracle`) with a run both captured, its dv penalty
    against the oracle in each such run (`oracle_score.PENALTY`) over the oracle's dv in that run,
    the oracle's line (zero penalty) drawn, the axis clipped to the penalty's far-out fences with
    the runs beyond marked (`plot_axes`); the title says how many of the law's runs are scored and
    how many it did not capture (those have no penalty). The laws without a scored run are named
    under the panels."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from aotv_cosim.campaigns.plot_axes import Scale, classes_of, scatter_by_outcome

    penalty = {law: np.array([float(r[oracle_score.PENALTY]) for r in rows]) for law, rows in rows_by_law.items()
               if law != oracle}
    laws = [law for law, y in penalty.items() if np.isfinite(y).any()]
    ncols = min(4, max(1, len(laws)))
    nrows = max(1, -(-len(laws) // ncols))
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.2 * ncols, 3.4 * nrows + 0.4), squeeze=False)
    for ax, law in zip(axes.flat, laws):
        rows, y = rows_by_law[law], penalty[law]
        scored = np.isfinite(y)
        x = np.array([float(r[oracle_score.ORACLE_DV]) for r in rows])
        captured = sum(r["outcome"] == "captured" for r in rows)
        ax.set_title(f"{law}: {int(scored.sum())} of {len(rows)} runs scored\n({len(rows) - captured} not captured "
                     "by the law: no penalty)", fontsize=8)
        handles = scatter_by_outcome(ax, x[scored], y[scored], np.array(classes_of(rows), dtype=object)[scored],
                                     Scale(oracle_score.PENALTY, y[scored]))
        line = ax.axhline(0.0, color="black", lw=0.8, zorder=1)
        below = int((y[scored] < 0.0).sum())
        below_text = f"; {below} run{'s' if below > 1 else ''} below it" if below else ""
        labels = {f"the oracle (no penalty){below_text}": line}
        labels.update({k: v for k, v in handles.items() if " the axis " in k})
        ax.legend(handles=list(labels.values()), labels=list(labels), fontsize=6, loc="best")
        ax.set_xlabel("the oracle's correction dv [m/s]", fontsize=8)
        ax.set_ylabel("dv penalty [m/s]", fontsize=8)
        axes_style(ax)
    for ax in list(axes.flat)[len(laws):]:
        ax.axis("off")
    fig.suptitle(f"dv penalty against the oracle ({oracle}), run by run", fontsize=9)
    unscored = [law for law in penalty if law not in laws]
    if unscored:
        fig.text(0.5, 0.01, f"no penalty to draw (no run captured by both the law and the oracle): "
                 f"{', '.join(unscored)}", ha="center", fontsize=8)
    fig.tight_layout(rect=(0, 0.04 if unscored else 0, 1, 1))
    fig.savefig(out_dir / "penalty.png", dpi=90)
    plt.close(fig)
    return "penalty.png"


def _shown(law, oracle) -> str:
    """A law's name on the plots: the set's oracle marked as the bound."""
    if law != oracle:
        return law
    return f"{law}: bound" if "oracle" in law else f"{law} (oracle): bound"


def _outcome_panel(ax, rows_by_law, laws, names) -> None:
    """The share of each outcome class per law (named `names` on the axis), stacked bars in the
    classes' colours."""
    from aotv_cosim.campaigns.plot_axes import OUTCOME_COLORS

    bottom = np.zeros(len(laws))
    for cls, color in OUTCOME_COLORS.items():
        share = np.array([100.0 * sum(r["outcome"] == cls for r in rows_by_law[law]) / max(1, len(rows_by_law[law]))
                          for law in laws])
        ax.bar(range(1, len(laws) + 1), share, bottom=bottom, color=color, width=0.6, label=cls.replace("_", " "))
        bottom += share
    ax.set_xticks(range(1, len(laws) + 1), names, fontsize=7, rotation=30, ha="right")
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
