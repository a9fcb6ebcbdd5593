"""Comparison study of seed 000: every guidance law through the same dispersed atmosphere.

A comparison file (schema aotv_cosim/schemas/compare.schema.json, e.g. scenarios/aotv_compare.json)
names the laws, each by a wiring file whose components include `vehicle` and `guidance`, and the
values applied to all of them (atmosphere dispersion, entry state). Each law is co-simulated from
the same start until the vehicle climbs back through the exit altitude (or the stop time), and

- `comparison.csv` gets one row per law (`COLUMNS`): exit time and the errors in speed and
  flight-path angle at the exit crossing (the altitude error is zero there by construction; a law
  that never exits reports its altitude error at the stop time instead), |u|max, integral of u^2,
  peak heating, minimum altitude, the Keplerian apogee and circularisation dv after exit (extraction
  Sec. 7) and the guidance's solve time, every column in SI with its unit in its name;
- `comparison.png` overlays altitude, speed, flight-path angle, command and heating versus time;
- each law's own run folder (time series, summary.json) sits under the output folder.
"""

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from aotv_cosim.model.documents import load_document
from aotv_cosim.errors import InputError
from aotv_cosim.fmu.build import built_fmu
from aotv_cosim.status import Status
from aotv_cosim.physics.planar import EXIT_000
from aotv_cosim.output.runner import run_scenario
from aotv_cosim.model.scenario import Scenario, StopCondition
from aotv_cosim.simulation.loading import load_system

SIGNALS = ("vehicle.h", "vehicle.v", "vehicle.gamma", "vehicle.qdot", "vehicle.int_u2",
           "vehicle.apogee_alt", "vehicle.dv_circ", "guidance.u")
"""Signals recorded for every law (plus guidance.solve_time when the law reports one)."""

COLUMNS = ("law", "fmu", "exited", "t_exit_s", "dh_exit_m", "dv_exit_m_s", "dgamma_exit_rad",
           "u_abs_max_m_s2", "int_u2_m2_s3", "qdot_max_W_m2", "h_min_m", "apogee_alt_m",
           "dv_circ_m_s", "solve_time_s")
"""comparison.csv columns, each in SI (its unit is the end of its name)."""


@dataclass
class Comparison:
    """A loaded comparison file: labels -> wiring paths, shared overrides, exit targets, times."""

    path: Path
    laws: dict
    parameters: dict
    exit_target: tuple
    start: float
    stop: float
    step: float
    description: str = ""


def load_comparison(path) -> Comparison:
    """Read and validate a comparison file (strict JSON, compare.schema.json)."""
    path = Path(path).resolve()
    doc = load_document(path, "compare")
    target = doc.get("exit", {})
    default = dict(zip(("h", "v", "gamma"), EXIT_000))
    comparison = Comparison(
        path=path, laws={k: (path.parent / v).resolve() for k, v in doc["laws"].items()},
        parameters=dict(doc.get("parameters", {})),
        exit_target=tuple(float(target.get(k, default[k])) for k in ("h", "v", "gamma")),
        start=float(doc.get("start", 0.0)), stop=float(doc.get("stop", 400.0)), step=float(doc["step"]),
        description=doc.get("description", ""))
    if not comparison.stop > comparison.start:
        raise InputError(f"stop ({comparison.stop}) must be after start ({comparison.start})", file=path,
                         entry="stop", fix="give a later stop time")
    return comparison


def _scenario(comparison: Comparison, label: str) -> Scenario:
    """The run of one law: its wiring with the shared overrides, stopped at the exit crossing."""
    system = load_system(comparison.laws[label], comparison.parameters, overrides_file=comparison.path,
                         fmus=built_fmu)
    for comp in ("vehicle", "guidance"):
        if comp not in system.components:
            raise InputError(f"the wiring has no component named {comp!r}", file=system.path,
                             entry=f"laws.{label}", fix="name the vehicle 'vehicle' and the law 'guidance'")
    outputs = set(system.outputs())
    record = [s for s in (*SIGNALS, "guidance.solve_time") if s in outputs]
    missing = [s for s in SIGNALS if s not in outputs]
    if missing:
        raise InputError(f"the wiring lacks {', '.join(missing)}", file=system.path, entry=f"laws.{label}",
                         fix="use a PointMassVehicle and a guidance FMU with output u")
    return Scenario(path=comparison.path.with_name(f"{comparison.path.stem}[{label}].json"), system=system,
                    start=comparison.start, stop=comparison.stop, step=comparison.step,
                    stop_conditions=[StopCondition("vehicle.h", comparison.exit_target[0], "up")],
                    record=record, description=f"{comparison.description} [{label}]")


def _read_series(folder: Path):
    """(header, times, rows) of a run's timeseries.csv."""
    with open(folder / "timeseries.csv") as f:
        header = f.readline().strip().split(",")
    data = np.loadtxt(folder / "timeseries.csv", delimiter=",", skiprows=1, ndmin=2)
    return header[1:], data[:, 0], data[:, 1:]


def summarize(label, fmu, summary, columns, rows, exit_target) -> dict:
    """One table row (see COLUMNS) from a law's run: its `output.summary.RunSummary` and recorded rows."""
    col = {name: rows[:, k] for k, name in enumerate(columns)}
    event = summary.event
    at_exit = event["values"] if event else {s: summary.final[s] for s in columns}
    hf, vf, gammaf = exit_target
    solve = col.get("guidance.solve_time")
    return {
        "law": label, "fmu": fmu, "exited": bool(event),
        "t_exit_s": event["time"] if event else math.nan,
        "dh_exit_m": at_exit["vehicle.h"] - hf,
        "dv_exit_m_s": at_exit["vehicle.v"] - vf,
        "dgamma_exit_rad": at_exit["vehicle.gamma"] - gammaf,
        "u_abs_max_m_s2": float(np.max(np.abs(col["guidance.u"]))),
        "int_u2_m2_s3": at_exit["vehicle.int_u2"],
        "qdot_max_W_m2": float(np.max(col["vehicle.qdot"])),
        "h_min_m": float(np.min(col["vehicle.h"])),
        "apogee_alt_m": at_exit["vehicle.apogee_alt"],
        "dv_circ_m_s": at_exit["vehicle.dv_circ"],
        "solve_time_s": float(solve[0]) if solve is not None else math.nan,
    }


def run_comparison(comparison: Comparison, out_dir, progress=None, make_plots=True):
    """Fly every law of `comparison`; write comparison.csv (and comparison.png) in out_dir.

    progress(label) is called before each law. Returns the table rows (dicts keyed by COLUMNS).
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    table, series = [], {}
    for label in comparison.laws:
        if progress:
            progress(label)
        scenario = _scenario(comparison, label)
        summary = run_scenario(scenario, out_dir / label, make_plots=False)
        if summary.status != Status.COMPLETED:
            raise InputError(f"the run of {label} failed: {summary.error}", file=comparison.path,
                             entry=f"laws.{label}", fix=f"see {out_dir / label / 'summary.json'}")
        columns, times, rows = _read_series(out_dir / label)
        fmu = scenario.system.components["guidance"].fmu.model_identifier
        table.append(summarize(label, fmu, summary, columns, rows, comparison.exit_target))
        series[label] = (columns, times, rows)
    write_table(table, out_dir / "comparison.csv")
    if make_plots:
        plot_overlay(series, out_dir / "comparison.png", comparison.description)
    return table


def write_table(table, path: Path) -> None:
    """comparison.csv: COLUMNS, numbers with 10 significant digits."""
    with open(path, "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(COLUMNS)
        for row in table:
            writer.writerow([f"{row[c]:.10g}" if isinstance(row[c], float) else row[c] for c in COLUMNS])


def format_table(table) -> str:
    """The table as aligned text for the terminal; the header gives each column's unit (heating
    in W/m^2 as in the files; altitudes converted to km, flight-path angle to mrad, solve time to ms)."""
    head = (f"{'law':<22}{'t_exit s':>9}{'dv m/s':>9}{'dgam mrad':>10}{'|u|max m/s2':>12}{'int u2 m2/s3':>13}"
            f"{'qdot max W/m2':>14}{'hmin km':>9}{'apogee km':>10}{'dv_circ m/s':>12}{'solve ms':>9}")
    lines = [head]
    for r in table:
        lines.append(f"{r['law']:<22}{r['t_exit_s']:9.2f}{r['dv_exit_m_s']:9.3f}"
                     f"{r['dgamma_exit_rad'] * 1e3:10.4f}{r['u_abs_max_m_s2']:12.3f}{r['int_u2_m2_s3']:13.2f}"
                     f"{r['qdot_max_W_m2']:14.0f}{r['h_min_m'] * 1e-3:9.3f}{r['apogee_alt_m'] * 1e-3:10.1f}"
                     f"{r['dv_circ_m_s']:12.2f}{r['solve_time_s'] * 1e3:9.1f}")
    return "\n".join(lines)


PANELS = (("vehicle.h", "altitude [km]", 1e-3), ("vehicle.v", "speed [m/s]", 1.0),
          ("vehicle.gamma", "flight-path angle [mrad]", 1e3), ("guidance.u", "command u [m/s^2]", 1.0),
          ("vehicle.qdot", "heating [W/m^2]", 1.0))
"""(signal, axis label with the plotted unit, factor from the SI value to it) of comparison.png."""


def plot_overlay(series, path: Path, title: str) -> None:
    """comparison.png: one panel per PANELS quantity, one curve per law, against time."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(len(PANELS), 1, figsize=(9, 2.4 * len(PANELS)), sharex=True)
    for ax, (signal, label, scale) in zip(axes, PANELS):
        for law, (columns, times, rows) in series.items():
            ax.plot(times, rows[:, columns.index(signal)] * scale, lw=1.1, label=law)
        ax.set_ylabel(label, fontsize=8)
        ax.grid(alpha=0.3)
        ax.tick_params(labelsize=7)
    axes[0].legend(fontsize=7, ncol=4)
    axes[-1].set_xlabel("time [s]")
    fig.suptitle(title[:120], fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
