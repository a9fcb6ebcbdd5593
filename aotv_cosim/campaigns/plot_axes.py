"""The axes of the campaign plots engineers read: one colour per outcome class everywhere, the
apogee error on a symmetric-log axis around its capture band, every other value on an axis clipped
to its far-out fences with the runs beyond marked, not dropped.

Why two treatments. The apogee error is signed and spans five orders of magnitude in one campaign:
metres for a law on target, the +-10 km band, thousands of km for a skip-out (+3,500 and +6,400 km
in the AFE set's time-linear law), and a linear axis drawn to the skip-outs flattens the band to a
line. A symmetric-log axis linear within the band (`linthresh` = band) keeps the band readable and
every run on the plot, each decade outside it equally wide. Other columns (correction dv, peak heat
rate, load factor, a dispersed input) are one-signed and mostly compact, with a few runs far out (the
dv of those skip-outs): a log axis would distort their body, so the axis is clipped to Tukey's
far-out fences (first quartile - 3 IQR, third quartile + 3 IQR; none of a normal sample's
1000 runs lies beyond them with probability 0.998) and each run beyond is drawn on the axis's edge
as a triangle pointing out (a scatter) or counted in a hatched edge bar (a histogram), with how
many and how far in the legend. When no run lies beyond the fences the axis is the data's range.
"""

import numpy as np

OUTCOME_COLORS = {"captured": "tab:green", "skip_out": "tab:orange", "undershoot": "tab:blue",
                  "impact": "black", "failed": "tab:red"}
"""Colour of each outcome class, in every campaign, benchmark and sweep plot."""
OTHER_COLOR = "tab:gray"
"""Colour of a run without an outcome class (a scenario that does not classify its runs)."""
FENCE_IQR = 3.0
"""Tukey's far-out fences: this many interquartile ranges beyond the quartiles."""
SYMLOG_COLUMN = "outcome.apogee_error"
"""The column drawn on a symmetric-log axis (module docstring)."""


def color_of(outcome) -> str:
    return OUTCOME_COLORS.get(outcome, OTHER_COLOR)


def fences(x: np.ndarray) -> tuple:
    """(low, high) of the clipped axis of the finite values `x` (not empty): Tukey's far-out fences,
    or the data's range where it lies within them."""
    q1, q3 = np.percentile(x, (25.0, 75.0))
    spread = FENCE_IQR * (q3 - q1)
    return max(float(x.min()), q1 - spread), min(float(x.max()), q3 + spread)


class Scale:
    """How one column is drawn (module docstring): `symlog` with `linthresh` (display units), or
    clipped to `limits` (display units; None when no run lies beyond the fences)."""

    def __init__(self, column, values, band=None):
        """values: the column's finite values in display units; band: the capture band's
        half-width in display units (the symlog's linear part), for the apogee error."""
        self.column = column
        self.symlog = column == SYMLOG_COLUMN and band is not None
        self.linthresh = band
        self.limits = None
        if not self.symlog and len(values):
            low, high = fences(values)
            if low > values.min() or high < values.max():
                self.limits = (low, high)

    def apply(self, ax, axis="y") -> None:
        """Set the axis's scale (symlog) or its clipped limits, padded so the edge markers show."""
        if self.symlog:
            (ax.set_yscale if axis == "y" else ax.set_xscale)("symlog", linthresh=self.linthresh)
        elif self.limits is not None:
            low, high = self.limits
            pad = 0.04 * (high - low) or 1.0
            (ax.set_ylim if axis == "y" else ax.set_xlim)(low - pad, high + pad)

    def beyond(self, values) -> tuple:
        """(below, above) boolean masks of the values outside the clipped limits."""
        values = np.asarray(values, dtype=float)
        if self.limits is None:
            return np.zeros(values.shape, bool), np.zeros(values.shape, bool)
        return values < self.limits[0], values > self.limits[1]

    def bins(self, values, count: int) -> np.ndarray:
        """`count` histogram bin edges over the drawn range: even on the symlog axis (in its
        transform), even within the clipped limits otherwise."""
        if self.symlog:
            t = _symlog(values, self.linthresh)
            return _symlog_inverse(np.linspace(t.min(), t.max(), count + 1), self.linthresh)
        low, high = self.limits if self.limits is not None else (values.min(), values.max())
        return np.linspace(low, high, count + 1)


def _symlog(x, linthresh):
    x = np.asarray(x, dtype=float)
    a = np.abs(x) / linthresh
    return np.sign(x) * np.where(a <= 1.0, a, 1.0 + np.log10(np.maximum(a, 1.0)))


def _symlog_inverse(t, linthresh):
    a = np.abs(t)
    return np.sign(t) * linthresh * np.where(a <= 1.0, a, 10.0 ** (a - 1.0))


def scatter_by_outcome(ax, x, y, classes, scale: Scale, floor_label=True) -> dict:
    """Points (x, y) coloured by their outcome class on the axis `scale` gives y; runs beyond
    its clipped limits as triangles on the edge, runs with no finite y (impact, failed, no exit)
    as crosses on the bottom edge. Returns {legend label: handle} of what was drawn."""
    import matplotlib.pyplot as plt

    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    classes = np.asarray(classes, dtype=object)
    finite = np.isfinite(y)
    scale.apply(ax)
    below, above = scale.beyond(np.where(finite, y, 0.0))
    inside = finite & ~below & ~above
    handles = {}
    for cls in dict.fromkeys(classes):
        pick = classes == cls
        if (pick & inside).any():
            ax.plot(x[pick & inside], y[pick & inside], ".", ms=3.5, alpha=0.75, color=color_of(cls))
        handles[_name(cls)] = plt.Line2D([], [], marker="o", ls="", color=color_of(cls), label=_name(cls))
    if scale.limits is not None:
        for mask, edge, marker, side in ((below, scale.limits[0], "v", "below"),
                                         (above, scale.limits[1], "^", "above")):
            mask = mask & finite
            if mask.any():
                ax.scatter(x[mask], np.full(mask.sum(), edge), marker=marker, s=22,
                           c=[color_of(c) for c in classes[mask]],
                           edgecolors="black", linewidths=0.4, zorder=3, clip_on=False)
                label = f"{mask.sum()} {side} the axis (to {_extreme(y[mask], side):.4g})"
                handles[label] = plt.Line2D([], [], marker=marker, ls="", color="0.5", markeredgecolor="black",
                                            label=label)
    missing = ~finite
    if missing.any() and floor_label:
        low = ax.get_ylim()[0]
        ax.scatter(x[missing], np.full(missing.sum(), low), marker="x", s=16, c=[color_of(c) for c in classes[missing]],
                   zorder=3, clip_on=False)
        ax.set_ylim(bottom=low)
        label = f"{missing.sum()} without a value (no exit, impact, failed)"
        handles[label] = plt.Line2D([], [], marker="x", ls="", color="0.3", label=label)
    return handles


def histogram_by_outcome(ax, values, classes, scale: Scale, count: int) -> dict:
    """A histogram of `values` (finite, display units) stacked by outcome class, on the axis
    `scale` gives x; runs beyond its clipped limits counted in hatched bars on the edges. Returns
    {legend label: handle}."""
    import matplotlib.pyplot as plt

    values, classes = np.asarray(values, dtype=float), np.asarray(classes, dtype=object)
    below, above = scale.beyond(values)
    inside = ~below & ~above
    edges = scale.bins(values[inside] if inside.any() else values, count)
    order = [c for c in OUTCOME_COLORS if c in set(classes)] + [c for c in dict.fromkeys(classes)
                                                                 if c not in OUTCOME_COLORS]
    stacks = [values[inside & (classes == c)] for c in order]
    ax.hist(stacks, bins=edges, stacked=True, color=[color_of(c) for c in order], alpha=0.85)
    scale.apply(ax, axis="x")
    handles = {_name(c): plt.Rectangle((0, 0), 1, 1, color=color_of(c), label=_name(c)) for c in order}
    if scale.limits is not None:
        width = (edges[-1] - edges[0]) / count
        for mask, edge, side, offset in ((below, scale.limits[0], "below", -width),
                                         (above, scale.limits[1], "above", 0.0)):
            if mask.any():
                ax.bar(edge + offset, mask.sum(), width=width, align="edge", color="none", edgecolor="black",
                       hatch="///", linewidth=0.6)
                label = f"{mask.sum()} {side} the axis (to {_extreme(values[mask], side):.4g})"
                handles[label] = plt.Rectangle((0, 0), 1, 1, facecolor="none", edgecolor="black", hatch="///",
                                               label=label)
    return handles


def band_patch(ax, band, axis="y", label=None):
    """The capture band +-band (display units) shaded on the y (or x) axis."""
    span = ax.axhspan if axis == "y" else ax.axvspan
    return span(-band, band, color="tab:green", alpha=0.15, zorder=0, label=label)


def _extreme(values, side) -> float:
    return float(np.min(values) if side == "below" else np.max(values))


def _name(cls) -> str:
    return str(cls).replace("_", " ") if isinstance(cls, str) else "run"


def classes_of(rows) -> list:
    """Each row's outcome class ("failed" for a run that did not complete, None without classes)."""
    return [r.get("outcome") if isinstance(r.get("outcome"), str) else None for r in rows]
