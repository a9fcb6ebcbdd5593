"""Write the seed 002 regression scenarios: `python -m aotv_cosim.studies.entry_scenarios`.

One scenario per perturbation of the paper's set (`guidance.entry_tracking_study.PERTURBATIONS`)
and per plant (ideal: drag at alpha_ref; full: drag at the commanded alpha), plus the nominal
(unperturbed) runs, as scenarios/entry_<plant>_<case>.json over scenarios/systems/entry_tracking_
<plant>.json. Each stops where the energy reaches the reference's terminal energy E_f and checks the
downrange and crossrange errors r0 dtheta, r0 dphi there (extraction A14, A16): ideal plant
against the paper's 1 n mi (nominal: the measured coupling-error bound, plus the terminal altitude
and Mach); full plant against the figures measured in docs/seed002.md, since the paper's bound is
not reached there.
"""

import json
from pathlib import Path

from aotv_cosim.guidance.entry_tracking_reference import read_table
from aotv_cosim.studies.entry_tracking_study import PERTURBATIONS
from aotv_cosim.physics import sx2

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
PAPER_BOUND_NMI = 1.0
"""The paper: "final errors in downrange and crossrange ... less than 1 n mile in all cases"."""
NOMINAL_BOUND_NMI = 0.35
"""Zero perturbation: the law returns u_ref, so the error is the co-simulation's coupling error
(zero-order hold of density and commands over the step). Measured downrange -0.329 n mi at
0.1 s and -0.166 n mi at 0.05 s (first order in the step, -> 0 with it); crossrange -0.013."""
FULL_MEASURED_NMI = {
    "nominal": (-0.681, -0.154), "r_plus": (-15.951, 8.802), "r_minus": (-7.986, -3.426),
    "theta_plus": (0.815, -0.459), "theta_minus": (-2.311, 0.230), "phi_plus": (-40.421, -7.102),
    "phi_minus": (-32.954, 11.008), "v_plus": (-3.930, -4.126), "v_minus": (-409.342, -55.516),
    "gamma_plus": (-9.089, 5.616), "gamma_minus": (-2.515, -2.581), "chi_plus": (-2.046, -1.214),
    "chi_minus": (-1.042, 1.393), "combined": (1.278, -0.200),
}
"""Full plant (drag at the commanded alpha), design of systems/entry_tracking_full.json (omega 20,
zeta 0.7, no integral terms, the paper's inversion): final (downrange, crossrange) errors in n mi
measured at 0.1 s (docs/seed002.md, full-plant study). The paper's < 1 n mi is not reached; these
figures are the regression values."""
FULL_TOLERANCE = (0.1, 0.05)
"""Full-plant regression tolerance: max(0.1 n mi, 5 % of the figure)."""
RECORD = ["vehicle.h", "vehicle.mach", "vehicle.drag_acc", "vehicle.downrange", "vehicle.crossrange",
          "guidance.downrange_error", "guidance.crossrange_error", "guidance.alpha_cmd",
          "guidance.sigma_cmd", "guidance.alpha_ref", "guidance.sigma_ref", "guidance.alpha_low",
          "guidance.alpha_high", "guidance.sigma_low", "guidance.sigma_high", "guidance.h_ref",
          "guidance.mach_ref", "guidance.drag_ref", "guidance.downrange_ref", "guidance.crossrange_ref",
          "guidance.constrained", "guidance.energy"]
OVERRIDES = ("vehicle.h0", "vehicle.theta0", "vehicle.phi0", "vehicle.v0", "vehicle.gamma0", "vehicle.psi0")


def initial_parameters(perturbation) -> dict:
    """Vehicle entry-state overrides for [dr, dtheta, dphi, dV, dgamma, dchi] (m, rad, m/s)."""
    base = (sx2.H0, 0.0, 0.0, sx2.V0, 0.0, 0.0)
    return {name: b + d for name, b, d in zip(OVERRIDES, base, perturbation) if d != 0.0}


def error_expectations(bound_nmi, source, note):
    """Downrange and crossrange errors at the terminal-energy event within +-bound_nmi."""
    return [{"signal": f"guidance.{channel}_error", "at": "event", "value": 0.0,
             "tolerance": round(bound_nmi * sx2.NMI, 1), "source": source, "note": note}
            for channel in ("downrange", "crossrange")]


def measured_expectations(figures_nmi):
    """Full plant: the measured final errors as regression values (the paper's bound is not met)."""
    floor, rel = FULL_TOLERANCE
    return [{"signal": f"guidance.{channel}_error", "at": "event", "value": round(value * sx2.NMI, 1),
             "tolerance": round(max(floor, rel * abs(value)) * sx2.NMI, 1),
             "source": "docs/seed002.md full-plant study: measured final error (paper: < 1 n mi, not reached)",
             "note": f"{value} n mi at 0.1 s; tolerance max(0.1 n mi, 5 %)"}
            for channel, value in zip(("downrange", "crossrange"), figures_nmi)]


def terminal_expectations(table):
    """Altitude and Mach at E_f: the reference's (paper: about 84,000 ft, close to Mach 2.7)."""
    return [
        {"signal": "vehicle.h", "at": "event", "value": round(84000.0 * sx2.FT, 1), "tolerance": 100.0,
         "source": "seed 002 simulation results: final altitude about 84,000 ft (T8)",
         "note": f"reference design ends at {table['h'][-1] / sx2.FT:.0f} ft; 100 m = 328 ft"},
        {"signal": "vehicle.mach", "at": "event", "value": 2.7, "tolerance": 0.01,
         "source": "seed 002 simulation results: velocity close to Mach 2.7 (T8)",
         "note": "E_f is defined as the reference's Mach 2.7 energy (US76 speed of sound)"},
    ]


def scenario(plant, case, perturbation, table) -> dict:
    """The scenario document of one plant and case."""
    e_final = float(table["energy"][-1])
    if case == "nominal" and plant == "ideal":
        expectations = error_expectations(
            NOMINAL_BOUND_NMI, "seed 002 extraction 6.2: zero perturbation gives zero error",
            "u = u_ref on the reference; discretization only") + terminal_expectations(table)
    elif plant == "ideal":
        expectations = error_expectations(
            PAPER_BOUND_NMI, "seed 002 simulation results: final errors < 1 n mile in all cases",
            "ideal plant (drag at alpha_ref): the law's own model")
    else:
        expectations = measured_expectations(FULL_MEASURED_NMI[case])
    return {
        "$schema": "../aotv_cosim/schemas/scenario.schema.json",
        "description": f"Seed 002 tracking, {plant} plant, perturbation {case} "
                       f"[dr, dtheta, dphi, dV, dgamma, dchi] = {list(perturbation)} (m, rad, m/s); "
                       "stops at the reference's terminal energy E_f (Mach 2.7).",
        "system": f"systems/entry_tracking_{plant}.json",
        "start": 0.0, "stop": 1000.0, "step": 0.1,
        "parameters": initial_parameters(perturbation),
        "stop_conditions": [{"signal": "guidance.energy", "crosses": e_final, "direction": "down",
                             "description": "terminal energy E_f of the reference (Mach 2.7)"}],
        "record": RECORD,
        "expectations": expectations,
    }


def main():
    table = read_table()
    cases = {"nominal": (0.0,) * 6, **PERTURBATIONS}
    for plant in ("ideal", "full"):
        for case, perturbation in cases.items():
            path = SCENARIOS / f"entry_{plant}_{case}.json"
            path.write_text(json.dumps(scenario(plant, case, perturbation, table), indent=2) + "\n")
            print(f"wrote {path}")


if __name__ == "__main__":
    main()
