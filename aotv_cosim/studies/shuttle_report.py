"""Seed 003 report: runs the thesis and saturation scenarios, prints their metrics, draws figures.

    python -m aotv_cosim.studies.shuttle_report OUT_DIR      (about 2 min on one core)

Figures: the nominal glide and its coefficient histories (omega0, omega1, |f|, mu), alpha versus
time for every law at both start points, and, for the saturation study, alpha and the elevator
(command and applied, with the +-25 deg limits). Metrics per run: peak commanded and applied
delta_e, time saturated, settle time (|alpha| < 0.05 deg for good), overshoot (the most negative
alpha as a percentage of alpha_i) and the peak elevator torque.
"""

import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from aotv_cosim.physics import shuttle_trajectory as st
from aotv_cosim.physics.shuttle_pitch import FT
from aotv_cosim.output.runner import run_scenario
from aotv_cosim.simulation.loading import load_scenario
from aotv_cosim.studies.shipped import scenarios_dir

SCENARIOS = scenarios_dir()
LAWS = ("feedforward", "fl", "lqr", "adaptive")
THESIS = [f"{law}_{alt}" for alt in ("400kft", "150kft") for law in LAWS] + ["lqr_asymptotic_150kft"]
SATURATION = ["saturation_fl", "saturation_lqr_open", "saturation_lqr_feedback",
              "saturation_adaptive", "saturation_adaptive_antiwindup"]
LIMIT = math.radians(25.0)


def run(name: str, out: Path):
    """Run scenarios/shuttle_<name>.json into out/<name>; returns (times, {signal: array})."""
    run_scenario(load_scenario(SCENARIOS / f"shuttle_{name}.json"), out / name, make_plots=False)
    data = np.genfromtxt(out / name / "timeseries.csv", delimiter=",", names=True)
    return data["time"], {n: data[n.replace(".", "")] for n in (
        "pitch.alpha", "pitch.settle_time", "controller.delta_e", "elevator.position",
        "pitch.torque")}


def metrics(times, series) -> dict:
    """Peak command/applied (deg), time saturated (s), settle (s), overshoot (%), peak torque."""
    alpha, cmd, pos = series["pitch.alpha"], series["controller.delta_e"], series["elevator.position"]
    dt = np.diff(times, prepend=times[0])
    return {"cmd_deg": math.degrees(np.abs(cmd).max()), "applied_deg": math.degrees(np.abs(pos).max()),
            "saturated_s": float(dt[np.abs(cmd) > LIMIT + 1e-12].sum()),
            "settle_s": float(series["pitch.settle_time"][-1]),
            "overshoot_pct": float(100.0 * min(0.0, alpha.min()) / alpha[0]),
            "torque_Nm": float(np.abs(series["pitch.torque"]).max())}


def nominal_figure(out: Path):
    tr = st.fly()
    c = tr.coefficients()
    minutes = tr.t / 60.0
    fig, axes = plt.subplots(2, 4, figsize=(15, 6))
    for ax, (y, label) in zip(axes[0], [(tr.h / FT / 1e3, "h [kft]"), (tr.v / FT, "V [ft/s]"),
                                        (np.degrees(tr.gamma), "gamma [deg]"),
                                        (np.degrees(tr.alpha0), "alpha0 [deg]")]):
        ax.plot(minutes, y)
        ax.set_title(label)
    for ax, key in zip(axes[1], ("omega0", "omega1", "f", "mu")):
        ax.semilogy(minutes, np.abs(c[key]), label=f"|{key}|")
        if key == "f":
            ax.semilogy(minutes[c["f"] > 0], c["f"][c["f"] > 0], ".", ms=2, label="f > 0")
        ax.set_title(f"|{key}| (1.38)-(1.42)")
        ax.legend(fontsize=7)
    for ax in axes.flat:
        ax.set_xlabel("time [min]")
        ax.grid(alpha=0.3)
    fig.suptitle("Seed 003 reconstructed nominal glide and unified-equation coefficients")
    fig.tight_layout()
    fig.savefig(out / "seed003_nominal.png", dpi=90)
    plt.close(fig)


def alpha_figure(out: Path, results: dict, names, path: str, title: str):
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.2))
    for ax, alt in zip(axes, ("400kft", "150kft")):
        for name in names:
            if name.endswith(alt):
                t, s = results[name]
                ax.plot(t, np.degrees(s["pitch.alpha"]), lw=1.1, label=name.replace(f"_{alt}", ""))
        ax.axhspan(-0.05, 0.05, color="0.85")
        ax.set_title(f"start {alt}")
        ax.set_xlabel("time [s]")
        ax.set_ylabel("alpha [deg]")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(out / path, dpi=90)
    plt.close(fig)


def saturation_figure(out: Path, results: dict):
    fig, axes = plt.subplots(2, len(SATURATION), figsize=(4 * len(SATURATION), 6), sharex=True)
    for col, name in enumerate(SATURATION):
        t, s = results[name]
        axes[0, col].plot(t, np.degrees(s["pitch.alpha"]))
        axes[0, col].set_title(name.replace("saturation_", ""), fontsize=9)
        axes[1, col].plot(t, np.degrees(s["controller.delta_e"]), label="command")
        axes[1, col].plot(t, np.degrees(s["elevator.position"]), label="applied")
        for sign in (-1, 1):
            axes[1, col].axhline(25 * sign, color="k", ls="--", lw=0.8)
        axes[1, col].set_ylim(-60, 90)
        axes[1, col].set_xlabel("time [s]")
        axes[1, col].legend(fontsize=7)
    axes[0, 0].set_ylabel("alpha [deg]")
    axes[1, 0].set_ylabel("delta_e [deg] (limits +-25)")
    for ax in axes.flat:
        ax.grid(alpha=0.3)
    fig.suptitle("Saturation study, 150,000 ft, alpha_i = 15 deg, elevator +-25 deg")
    fig.tight_layout()
    fig.savefig(out / "seed003_saturation.png", dpi=90)
    plt.close(fig)


def main(out_dir: str):
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    nominal_figure(out)
    results = {name: run(name, out / "runs") for name in THESIS + SATURATION}
    print(f"{'run':34s} {'cmd deg':>9s} {'applied':>8s} {'sat s':>7s} {'settle s':>9s} "
          f"{'overshoot %':>11s} {'torque N m':>11s}")
    for name, (t, s) in results.items():
        m = metrics(t, s)
        print(f"{name:34s} {m['cmd_deg']:9.2f} {m['applied_deg']:8.2f} {m['saturated_s']:7.2f} "
              f"{m['settle_s']:9.2f} {m['overshoot_pct']:11.2f} {m['torque_Nm']:11.4g}")
    alpha_figure(out, results, THESIS, "seed003_alpha.png",
                 "alpha(t), alpha_i = 5 deg (grey band: +-0.05 deg)")
    saturation_figure(out, results)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "results/seed003_report")
