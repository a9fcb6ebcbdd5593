"""Figures of the seed-001 plane change, after Calise & Melamed, NASA CR-194523, Figs. 3.4-3.19.

The report's plots did not survive in the text (extraction Sec. 6.4-6.5: captions only), so these
are our own curves for the same quantities:

* Figs. 3.4-3.10, open-loop zeroth-order MAE solution from the Sec. 3.7.2 entry state, against
  heading psi: gamma (inner, outer, composite), speed, P_gamma, P_u, lambda, bank, altitude.
* Figs. 3.11-3.19, guided (MAE guidance FMU flying the vehicle FMU, scenario
  plane_change_mae_guided.json) against our numerically optimal solution, against time: gamma,
  speed, P_gamma, P_u, lambda, bank, Loh's term, altitude, and the speed near the end.

Optimal costates are put in the MAE normalization (J = u_f = V_f^2/(g_s r_s), r_s at the lowest
point): P_u = p_v V_f/V, P_gamma = p_gamma 2 V_f/(g_s r_s), with p = dV_f/dx.

    python -m aotv_cosim.studies.plane_change_plots [--out results/seed001_figures]
"""

import argparse
import math
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt

from aotv_cosim.guidance import mae, mae_solution
from aotv_cosim.guidance.plane_change_optimal import solve_optimal
from aotv_cosim.physics import mrrv
from aotv_cosim.studies.shipped import scenario
from aotv_cosim.status import Status

SCENARIO = scenario("plane_change_mae_guided.json")
ENTRY = mae.State(mrrv.R_EARTH + 60.0e3, 7851.0, math.radians(-1.35), 0.0)
TARGETS = mae.Targets(60.0e3, math.radians(1.0), math.radians(20.0))
END_WINDOW = 40.0
"""Length (s) of the end-of-trajectory window of Fig. 3.19."""


def _number(fig):
    """Report figure number from a file tag: '3_04' -> '3.4'."""
    chapter, number = fig.split("_")
    return f"{chapter}.{int(number)}"


def _figure(path, title, xlabel, ylabel, curves):
    """One PNG: curves is a list of (x, y, label, style)."""
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for x, y, label, style in curves:
        ax.plot(x, y, style, lw=1.4, label=label)
    ax.set_title(title, fontsize=10)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    if len(curves) > 1:
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path.name


def open_loop_curves(k: mae_solution.MaeConstants, psi: np.ndarray):
    """Inner, outer and composite gamma (deg), V (m/s), P_gamma, P_u along the open-loop composite.

    Outer values use the left side before the lowest point psi_s and the right side after it,
    at the composite altitude; inner values are the (3.61)-(3.64) functions of psi.
    """
    hist = mae_solution.open_loop(k, psi, mrrv.R_EARTH)
    h = (hist.z + mrrv.R_EARTH - k.r_s) / k.r_s
    left = psi < k.psi_s

    def outer(name):
        return np.where(left, getattr(k.left, name)(h), getattr(k.right, name)(h))

    inner_u = k.inner_u(psi)
    return hist, {
        "gamma": (np.degrees(k.inner.gamma(psi)), np.degrees(outer("gamma")), np.degrees(hist.gamma)),
        "speed": (np.sqrt(inner_u * k.gs_rs), np.sqrt(outer("u") * k.gs_rs), hist.v),
        "p_gamma": (k.inner.p_gamma(psi), outer("p_gamma"), hist.p_gamma),
        "p_u": (-k.e_star * k.inner.p_v / inner_u, outer("p_u"), hist.p_u),
    }


def open_loop_figures(out: Path):
    """Figs. 3.4-3.10 from the nominal open-loop zeroth-order MAE solution."""
    k = mae.solve(ENTRY, TARGETS).constants
    psi = np.linspace(0.0, TARGETS.psi_f, 401)
    hist, curves = open_loop_curves(k, psi)
    x, xl = np.degrees(psi), "heading psi [deg]"
    files = []
    for fig, key, title, ylabel in [("3_04", "gamma", "Flight-path angle", "gamma [deg]"),
                                    ("3_05", "speed", "Velocity", "V [m/s]"),
                                    ("3_06", "p_gamma", "Costate P_gamma", "P_gamma [-]"),
                                    ("3_07", "p_u", "Costate P_u", "P_u [-]")]:
        inner, outer, comp = curves[key]
        files.append(_figure(out / f"fig{fig}_open_loop_{key}.png", f"Fig. {_number(fig)}: "
                             f"{title}, zeroth-order open loop", xl, ylabel,
                             [(x, inner, "inner", "--"), (x, outer, "outer", ":"),
                              (x, comp, "composite", "-")]))
    for fig, key, y, title, ylabel in [("3_08", "lift", hist.lam, "Normalized lift", "lambda [-]"),
                                       ("3_09", "bank", np.degrees(hist.bank), "Bank angle", "mu [deg]"),
                                       ("3_10", "altitude", hist.z / 1e3, "Altitude", "z [km]")]:
        files.append(_figure(out / f"fig{fig}_open_loop_{key}.png", f"Fig. {_number(fig)}: "
                             f"{title}, zeroth-order open loop", xl, ylabel, [(x, y, "composite", "-")]))
    return files


def optimal_in_mae_units(opt):
    """(P_u, P_gamma, Loh's term) of the optimal solution in the MAE normalization (module doc)."""
    r_s = mrrv.R_EARTH + opt.z.min()
    gs_rs = mae.MaeModel().mu_earth / r_s
    p_u = opt.p_v * opt.v_f / opt.v
    p_gamma = opt.p_gamma * 2.0 * opt.v_f / gs_rs
    loh = np.array([mrrv.loh_term(mrrv.R_EARTH + z, v, mrrv.density(z), mae.MaeModel().mu_earth)
                    for z, v in zip(opt.z, opt.v)])
    return p_u, p_gamma, loh


def run_guided(out: Path, scenario_path: Path = SCENARIO) -> tuple[dict, float]:
    """Run the guided co-simulation into out/guided.

    Returns ({signal: array, 'time': array}, exit speed in m/s interpolated at the 60 km crossing).
    """
    from aotv_cosim.output.runner import run_scenario
    from aotv_cosim.simulation.loading import load_scenario

    run_dir = out / "guided"
    summary = run_scenario(load_scenario(scenario_path), run_dir, make_plots=False)
    if summary.status != Status.COMPLETED:
        raise RuntimeError(f"guided run failed: {summary.error}")
    data = np.genfromtxt(run_dir / "timeseries.csv", delimiter=",", names=True, deletechars="")
    assert data.dtype.names is not None and summary.event is not None  # named columns; the run ended at its event
    return {name: data[name] for name in data.dtype.names}, summary.event["values"]["vehicle.v"]


def guided_figures(out: Path, guided: dict, v_f: float, opt):
    """Figs. 3.11-3.19: guided co-simulation (exit speed v_f, m/s) against the optimal solution."""
    p_u, p_gamma, loh = optimal_in_mae_units(opt)
    t = guided["time"]
    rows = [("3_11", "gamma", "Flight-path angle", "gamma [deg]",
             np.degrees(guided["vehicle.gamma"]), np.degrees(opt.gamma)),
            ("3_12", "speed", "Velocity", "V [m/s]", guided["vehicle.v"], opt.v),
            ("3_13", "p_gamma", "Costate P_gamma", "P_gamma [-]", guided["guidance.p_gamma"], p_gamma),
            ("3_14", "p_u", "Costate P_u", "P_u [-]", guided["guidance.p_u"], p_u),
            ("3_15", "lift", "Normalized lift", "lambda [-]", guided["guidance.lam"], opt.lam),
            ("3_16", "bank", "Bank angle", "mu [deg]", np.degrees(guided["guidance.bank"]),
             np.degrees(opt.bank)),
            ("3_17", "loh", "Loh's term", "eps Mbar [-]", guided["vehicle.loh_term"], loh),
            ("3_18", "altitude", "Altitude", "z [km]", guided["vehicle.h"] / 1e3, opt.z / 1e3)]
    files = [_figure(out / f"fig{fig}_guided_{key}.png", f"Fig. {_number(fig)}: {title}, "
                     "guided vs optimal", "time [s]", ylabel,
                     [(t, g, "zeroth-order MAE guided", "-"), (opt.t, o, "optimal", "--")])
             for fig, key, title, ylabel, g, o in rows]
    g_end, o_end = t >= t[-1] - END_WINDOW, opt.t >= opt.t_f - END_WINDOW
    files.append(_figure(out / "fig3_19_guided_speed_end.png",
                         f"Fig. 3.19: optimal and guided performance (V_f {v_f:.1f} "
                         f"vs {opt.v_f:.1f} m/s)", "time [s]", "V [m/s]",
                         [(t[g_end], guided["vehicle.v"][g_end], "guided", "-"),
                          (opt.t[o_end], opt.v[o_end], "optimal", "--")]))
    return files


def make_all(out: Path, scenario_path: Path = SCENARIO):
    """Write every figure into out (created), the guided run from `scenario_path`; returns the
    file names."""
    out.mkdir(parents=True, exist_ok=True)
    files = open_loop_figures(out)
    files += guided_figures(out, *run_guided(out, Path(scenario_path)), solve_optimal(n_points=1001))
    return files


def main(argv=None):
    parser = argparse.ArgumentParser(description="Seed-001 figures (report Figs. 3.4-3.19)")
    parser.add_argument("--out", type=Path, default=Path("results") / "seed001_figures")
    args = parser.parse_args(argv)
    for name in make_all(args.out):
        print(args.out / name)


if __name__ == "__main__":
    main()
