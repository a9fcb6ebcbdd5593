"""Seed 002 closed loop in the energy domain (no FMUs): the design-study and verification tool.

Integrates the plant (eqs. 10-15) with the tracking law of `entry_tracking` in energy by classical
RK4 (the law evaluated at every stage, integral states int e dE carried as ODE states) from a
perturbed entry down to the reference's terminal energy E_f, and compares with the reference at
equal energy (extraction A14, A16). Two plants:

- "ideal": drag at alpha_ref(E) (the law's own model D = D~; extraction 6.2): the closed loop
  follows the designed linear error ODE up to the neglected u_ref' terms;
- "full": drag at the commanded alpha (the paper's simulation).

Perturbations follow the paper: [dr, dtheta, dphi, dV, dgamma, dchi] added to the time-domain
entry state (m, rad, m/s), so dV and dr move the entry energy (A23, A29).
"""

import math
from dataclasses import dataclass, field

import numpy as np

from aotv_cosim.guidance import entry_tracking as law
from aotv_cosim.guidance.entry_tracking_reference import Reference
from aotv_cosim.physics import entry, sx2

DEG = math.radians(1.0)
PERTURBATIONS = {
    "r_plus": (1000.0 * sx2.FT, 0, 0, 0, 0, 0), "r_minus": (-1000.0 * sx2.FT, 0, 0, 0, 0, 0),
    "theta_plus": (0, 0.1 * DEG, 0, 0, 0, 0), "theta_minus": (0, -0.1 * DEG, 0, 0, 0, 0),
    "phi_plus": (0, 0, 0.1 * DEG, 0, 0, 0), "phi_minus": (0, 0, -0.1 * DEG, 0, 0, 0),
    "v_plus": (0, 0, 0, 100.0 * sx2.FT, 0, 0), "v_minus": (0, 0, 0, -100.0 * sx2.FT, 0, 0),
    "gamma_plus": (0, 0, 0, 0, 0.1 * DEG, 0), "gamma_minus": (0, 0, 0, 0, -0.1 * DEG, 0),
    "chi_plus": (0, 0, 0, 0, 0, 0.1 * DEG), "chi_minus": (0, 0, 0, 0, 0, -0.1 * DEG),
    "combined": (1000.0 * sx2.FT, 0.1 * DEG, 0.1 * DEG, 0, 0, 0),
}
"""The paper's perturbation set: the 12 one-at-a-time extremes and the Figs. 1-6 combined case."""


@dataclass(frozen=True)
class Design:
    """Tunable choices of the law (none is given by the paper): poles, bands, eta, integral terms,
    control recovery (`entry_tracking.INVERSIONS`)."""

    omega1: float = 33.6
    zeta1: float = 0.7
    omega2: float = 33.6
    zeta2: float = 0.7
    bands: law.Bands = field(default_factory=lambda: law.Bands(
        5.0 * DEG, 5.0 * DEG, 25.0 * DEG, 90.0 * DEG, 80.0 * DEG))
    eta: float = 0.5
    integral: bool = True
    inversion: str = "paper"

    def gains(self) -> law.Gains:
        g = law.gains(self.omega1, self.zeta1, self.omega2, self.zeta2)
        if self.integral:
            return g
        return law.Gains((*g.k1[:3], 0.0), (*g.k2[:2], 0.0))


def entry_state(perturbation, reference: Reference):
    """(x = (r, theta, phi, gamma, chi), E) of the perturbed entry."""
    dr, dtheta, dphi, dv, dgamma, dchi = perturbation
    r = sx2.R_EARTH + sx2.H0 + dr
    e = float(entry.energy(r, sx2.V0 + dv))
    return np.array([r, dtheta, dphi, dgamma, dchi], float), e


@dataclass
class Run:
    """History of one closed-loop run (arrays over decreasing energy)."""

    energy: np.ndarray
    states: np.ndarray
    alpha: np.ndarray
    sigma: np.ndarray
    constrained: np.ndarray
    errors: np.ndarray


def simulate(perturbation, plant="full", design=Design(), reference=None, step=5e4 * sx2.FT ** 2):
    """Closed loop from the perturbed entry to E_f, RK4 in energy with |dE| <= step (m^2/s^2)."""
    reference = reference or Reference()
    g = design.gains()
    x, e = entry_state(perturbation, reference)
    y = np.concatenate([x, [0.0, 0.0]])

    def control(e, y):
        x_ref = reference.state(e)
        alpha_ref, sigma_ref = reference.controls(e)
        return law.command(y[:5], e, x_ref, alpha_ref, sigma_ref, y[5:], g, design.bands, design.eta,
                           design.inversion), x_ref

    def rates(e, y):
        cmd, x_ref = control(e, y)
        lift = entry.specific_lift_drag(y[0], e, cmd.alpha)[0]
        alpha_drag = reference.controls(e)[0] if plant == "ideal" else cmd.alpha
        drag = entry.specific_lift_drag(y[0], e, alpha_drag)[1]
        dx = entry.energy_derivatives(y[:5], e, lift * math.cos(cmd.sigma), lift * math.sin(cmd.sigma), drag)
        return np.array([*dx, y[1] - x_ref[1], y[2] - x_ref[2]])

    n = max(1, math.ceil((e - reference.e_final) / step))
    grid = np.linspace(e, reference.e_final, n + 1)
    history = []
    for k, e_k in enumerate(grid):
        cmd, x_ref = control(e_k, y)
        history.append((e_k, y[:5].copy(), cmd.alpha, cmd.sigma, cmd.constrained, y[1:3] - x_ref[1:3]))
        if k == n:
            break
        h = grid[k + 1] - e_k
        k1 = rates(e_k, y)
        k2 = rates(e_k + h / 2, y + h / 2 * k1)
        k3 = rates(e_k + h / 2, y + h / 2 * k2)
        k4 = rates(e_k + h, y + h * k3)
        y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    columns = list(zip(*history))
    return Run(*(np.array(c) for c in columns))
