"""Seed-000 thesis figures: the guidance laws' trajectories and the Table 8.1 comparison.

* Laws: every law of the shipped comparison file (scenarios/aotv_compare.json) flown from the
  Table 4.1 entry, each until it climbs back through the exit altitude, through the nominal
  atmosphere (`laws/`, the comparison's dispersion dropped: the thesis's trajectory figures, on
  which the laws' curves nearly coincide) and through the comparison's dispersed atmosphere
  (`dispersed/`, density x 1.1 with +-20 % noise, where they part): `comparison.png` overlays
  altitude, speed, flight-path angle, lift command u and heating against time and
  `comparison.csv` has the exit errors, |u|max, int u^2 and peak heating per law (SI).
* Table 8.1: the eleven scenarios aotv_table8_1_row*.json (the predictive law of Ch. 6 for
  eleven ballistic parameters K) run in memory; `table8_1.csv` lists per row and quantity
  (a in m/s^2, b in m/s^3, tf' in s, integral of |u| in m/s) the thesis value, the measured
  one and the relative error, and `table8_1.png` draws both against K.

    aotv-cosim figures seed000 [--out results/seed000_figures]   (about a minute on one core)
"""

import csv
import dataclasses
import math
from pathlib import Path

from aotv_cosim.studies.shipped import scenarios_dir

QUANTITIES = (("guidance.a", "a", "m/s2"), ("guidance.b", "b", "m/s3"), ("guidance.tf", "tf'", "s"),
              ("vehicle.int_abs_u", "int |u| dt", "m/s"))
"""(signal, thesis symbol, unit) of the Table 8.1 columns; each row scenario expects them at the end."""


def laws(out: Path, scenarios: Path, progress=None) -> list:
    """Fly every law of scenarios/aotv_compare.json undispersed into out/laws and as the file
    says into out/dispersed; returns the files."""
    from aotv_cosim.studies.compare import load_comparison, run_comparison

    comparison = load_comparison(scenarios / "aotv_compare.json")
    nominal = dataclasses.replace(comparison, parameters={},
                                  description="Seed 000 laws: Table 4.1 entry, nominal atmosphere")
    files = []
    for folder, study in (("laws", nominal), ("dispersed", comparison)):
        run_comparison(study, out / folder, progress=progress)
        files += [out / folder / "comparison.png", out / folder / "comparison.csv"]
    return files


def table_8_1(scenarios: Path, progress=None) -> list:
    """[{row, K, quantity, unit, thesis, measured, rel_error, passed}] of the Table 8.1 scenarios."""
    from aotv_cosim.output.runner import simulate
    from aotv_cosim.simulation.loading import load_scenario

    rows = []
    for path in sorted(scenarios.glob("aotv_table8_1_row*.json")):
        if progress:
            progress(path.stem)
        scenario = load_scenario(path)
        k_ball = scenario.system.components["guidance"].parameters["K_ball"]
        checks = {e["signal"]: e for e in simulate(scenario).summary.expectations}
        for signal, symbol, unit in QUANTITIES:
            e = checks[signal]
            measured = e["measured"] if e["measured"] is not None else math.nan
            rows.append({"row": int(path.stem[-2:]), "K_1_m": k_ball, "quantity": symbol, "unit": unit,
                         "thesis": e["expected"], "measured": measured,
                         "rel_error": measured / e["expected"] - 1.0, "passed": e["passed"]})
    return rows


def write_table(rows, path: Path) -> Path:
    """table8_1.csv: one line per row and quantity, numbers with 10 significant digits."""
    with open(path, "w", newline="") as f:
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow(list(rows[0]))
        for r in rows:
            writer.writerow([f"{v:.10g}" if isinstance(v, float) else v for v in r.values()])
    return path


def format_table(rows) -> str:
    """The Table 8.1 comparison as text: thesis, measured and relative error per row and quantity."""
    lines = [f"{'row':>3} {'K 1/m':>10} {'quantity':<11} {'unit':<5} {'thesis':>14} {'measured':>14} "
             f"{'rel. error':>11}  check"]
    for r in rows:
        lines.append(f"{r['row']:3d} {r['K_1_m']:10.4g} {r['quantity']:<11} {r['unit']:<5} {r['thesis']:14.7g} "
                     f"{r['measured']:14.7g} {r['rel_error']:11.2e}  {'pass' if r['passed'] else 'FAIL'}")
    return "\n".join(lines)


def plot_table(rows, path: Path) -> Path:
    """table8_1.png: each quantity against K, thesis and measured."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(10, 7))
    for ax, (_, symbol, unit) in zip(axes.flat, QUANTITIES):
        mine = [r for r in rows if r["quantity"] == symbol]
        k = [r["K_1_m"] for r in mine]
        ax.plot(k, [r["thesis"] for r in mine], "o", mfc="none", ms=8, label="thesis Table 8.1")
        ax.plot(k, [r["measured"] for r in mine], "x", ms=7, label="co-simulation")
        ax.set_xlabel("K [1/m]")
        ax.set_ylabel(f"{symbol} [{unit}]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Seed 000 Table 8.1: predictive time-linear law for eleven ballistic parameters K")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def make_all(out: Path, scenarios: Path | None = None, progress=None):
    """Write every figure and table into out (created); returns (files, Table 8.1 text)."""
    out = Path(out)
    scenarios = Path(scenarios) if scenarios else scenarios_dir()
    out.mkdir(parents=True, exist_ok=True)
    files = laws(out, scenarios, progress)
    rows = table_8_1(scenarios, progress)
    files += [write_table(rows, out / "table8_1.csv"), plot_table(rows, out / "table8_1.png")]
    return files, format_table(rows)
