"""Seed 002 Figs. 1-6 from a run of an entry_* scenario: `python -m aotv_cosim.studies.entry_plots RUN_DIR`.

RUN_DIR is the output folder of `aotv-cosim run scenarios/entry_<plant>_<case>.json` (its
timeseries.csv records the signals listed in `entry_scenarios.RECORD`). Writes fig1..fig6 PNGs
into RUN_DIR (or --out): 1 ground track (reference and actual), 2 downrange and crossrange errors
r0 dtheta, r0 dphi versus Mach, 3 alpha command with alpha_ref and its band, 4 bank command with
sigma_ref and its band, 5 altitude, 6 drag acceleration, reference and actual versus Mach (actual
curves against the actual Mach, reference curves against the reference Mach at the same energy,
extraction A27). Units: n mi, deg, ft, ft/s^2 as in the paper.
"""

import argparse
import csv
from pathlib import Path

import numpy as np

from aotv_cosim.errors import InputError
from aotv_cosim.physics import sx2

DEG = 180.0 / np.pi


def read_series(run_dir) -> dict:
    """{column: array} of RUN_DIR/timeseries.csv, which must record every signal of
    `entry_scenarios.RECORD`; InputError naming the file for a folder that holds no readable time
    series with rows, or one without those signals (the run of another scenario)."""
    from aotv_cosim.studies.entry_scenarios import RECORD

    path = Path(run_dir) / "timeseries.csv"
    fix = "give the folder of a run of an entry_* scenario (aotv-cosim run scenarios/entry_ideal_combined.json)"
    try:
        with open(path, newline="") as stream:
            rows = list(csv.reader(stream))
        data = np.array(rows[1:], dtype=float).reshape(len(rows) - 1, len(rows[0]))
    except (OSError, ValueError, IndexError) as exc:
        raise InputError(f"cannot read the run's time series: {getattr(exc, 'strerror', None) or exc}", file=path,
                         fix=fix) from None
    missing = [name for name in RECORD if name not in rows[0]]
    if missing or not len(data):
        cause = f"the run recorded no {', '.join(missing[:4])}{' ...' if len(missing) > 4 else ''}" if missing \
            else "the run recorded no row"
        raise InputError(cause, file=path, fix=fix)
    return {name: data[:, k] for k, name in enumerate(rows[0])}


def figures(s: dict):
    """[(file stem, title, [(x, y, label, style)], x label, y label, invert x)] of Figs. 1-6."""
    m, m_ref = s["vehicle.mach"], s["guidance.mach_ref"]
    nmi, ft = 1.0 / sx2.NMI, 1.0 / sx2.FT
    def g(name):
        return s[f"guidance.{name}"]

    return [
        ("fig1_ground_track", "Fig. 1 ground track", [
            (g("downrange_ref") * nmi, g("crossrange_ref") * nmi, "reference", "--"),
            (s["vehicle.downrange"] * nmi, s["vehicle.crossrange"] * nmi, "actual", "-")],
         "downrange, n mi", "crossrange, n mi", False),
        ("fig2_errors", "Fig. 2 tracking errors", [
            (m, g("downrange_error") * nmi, "r0 dtheta (downrange)", "-"),
            (m, g("crossrange_error") * nmi, "r0 dphi (crossrange)", "--")],
         "Mach", "error, n mi", True),
        ("fig3_alpha", "Fig. 3 angle of attack", [
            (m, g("alpha_cmd") * DEG, "commanded", "-"), (m_ref, g("alpha_ref") * DEG, "reference", "--"),
            (m_ref, g("alpha_low") * DEG, "alpha_low", ":"), (m_ref, g("alpha_high") * DEG, "alpha_high", ":")],
         "Mach", "alpha, deg", True),
        ("fig4_bank", "Fig. 4 bank angle", [
            (m, g("sigma_cmd") * DEG, "commanded", "-"), (m_ref, g("sigma_ref") * DEG, "reference", "--"),
            (m_ref, g("sigma_low") * DEG, "sigma_low", ":"), (m_ref, g("sigma_high") * DEG, "sigma_high", ":")],
         "Mach", "bank, deg", True),
        ("fig5_altitude", "Fig. 5 altitude", [
            (m_ref, g("h_ref") * ft, "reference", "--"), (m, s["vehicle.h"] * ft, "actual", "-")],
         "Mach", "altitude, ft", True),
        ("fig6_drag", "Fig. 6 drag acceleration", [
            (m_ref, g("drag_ref") * ft, "reference", "--"), (m, s["vehicle.drag_acc"] * ft, "actual", "-")],
         "Mach", "drag, ft/s^2", True),
    ]


def plot(run_dir, out_dir=None) -> list:
    """Write the six PNGs; returns their paths."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out_dir = Path(out_dir or run_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = []
    for stem, title, curves, xlabel, ylabel, invert in figures(read_series(run_dir)):
        fig, ax = plt.subplots(figsize=(6.4, 4.2))
        for x, y, label, style in curves:
            ax.plot(x, y, style, label=label)
        ax.set(title=title, xlabel=xlabel, ylabel=ylabel)
        if invert:
            ax.invert_xaxis()
        ax.grid(True, alpha=0.3)
        ax.legend()
        fig.tight_layout()
        path = out_dir / f"{stem}.png"
        fig.savefig(path, dpi=110)
        plt.close(fig)
        paths.append(path)
    return paths


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir")
    parser.add_argument("--out", default=None, help="output folder (default: RUN_DIR)")
    args = parser.parse_args(argv)
    for path in plot(args.run_dir, args.out):
        print(path)


if __name__ == "__main__":
    main()
