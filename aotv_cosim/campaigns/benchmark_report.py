"""The benchmark's scorecard as text (console, report.md) and its overlaid plots."""

import math

import numpy as np

from aotv_cosim.campaigns.figures import axes_style

OVERLAID = (("outcome.apogee_error", "apogee error [m]"), ("outcome.dv_total", "correction dv [m/s]"),
            ("outcome.peak_heat_rate", "peak heat rate [W/m2]"), ("outcome.int_abs_u", "int |u| dt [m/s]"))


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
    """The scorecard transposed (one column per law, one line per figure), for a terminal."""
    rows = table(cards, units)
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


def plots(out_dir, rows_by_law) -> list:
    """benchmark.png: each law's distribution of the OVERLAID columns (step histograms on common
    bins, completed runs with finite values)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(11, 7.5))
    for ax, (column, label) in zip(axes.flat, OVERLAID):
        data = {}
        for law, rows in rows_by_law.items():
            x = np.array([float(r[column]) for r in rows if r["status"] == "completed"], dtype=float)
            data[law] = x[np.isfinite(x)]
        every = np.concatenate([x for x in data.values() if len(x)] or [np.zeros(0)])
        if len(every) < 2 or np.ptp(every) == 0.0:
            ax.set_title(f"{label}: no spread", fontsize=9)
            continue
        bins = np.linspace(every.min(), every.max(), 40)
        for law, x in data.items():
            if len(x):
                ax.hist(x, bins=bins, histtype="step", lw=1.3, label=law)
        ax.set_xlabel(label, fontsize=8)
        ax.set_ylabel("runs", fontsize=8)
        axes_style(ax)
    axes.flat[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out_dir / "benchmark.png", dpi=90)
    plt.close(fig)
    return ["benchmark.png"]
