"""Seed 002 reference controls alpha_ref(E), sigma_ref(E) and their open-loop trajectory, SI units.

The paper obtains its reference "by open-loop integration of some chosen reference controls
alpha_ref(E) and sigma_ref(E)" from [h, V, gamma, chi] = [200,000 ft, 17,000 ft/s, 0, 0], with a
bank reversal at about 10,000 ft/s, ending at about 84,000 ft near Mach 2.7; it gives neither the
profiles nor the terminal energy (extraction Sec. 5, A13, A14, A24). This design (documented in
docs/seed002.md) is piecewise linear in energy, so a table holding its breakpoints reproduces it
exactly by linear interpolation:

- alpha_ref = 20 deg above E = 7.2e7 ft^2/s^2 (sqrt(2E) = 12,000 ft/s), linear down to 11.5 deg at
  E = 1.25e7 ft^2/s^2 (sqrt(2E) = 5,000 ft/s), constant below: high alpha while heating peaks, the
  front side of the L/D curve (alpha* = 14.07 deg) at the end;
- sigma_ref = +35 deg above E = 5.6e7 ft^2/s^2, a linear reversal to -20 deg at 5.4e7 ft^2/s^2
  (V_ref = 10,000 ft/s at its centre), -20 deg below;
- the end is the energy where the reference reaches Mach 2.7 (US76 speed of sound): 84,000 ft
  within a few hundred feet;
- above the entry energy both controls stay at their entry values, and the trajectory is
  integrated backwards from the entry state to E0 + 3e6 ft^2/s^2 so that the +100 ft/s and
  +1000 ft perturbations start on the reference (A15).
"""

import math

import numpy as np

from aotv_cosim.physics import entry, sx2

FT2 = sx2.FT * sx2.FT
"""m^2/s^2 per ft^2/s^2."""
ALPHA_BREAKS = ((1.25e7 * FT2, math.radians(11.5)), (7.2e7 * FT2, math.radians(20.0)))
"""(E m^2/s^2, alpha_ref rad) breakpoints, increasing E; constant outside."""
SIGMA_BREAKS = ((5.4e7 * FT2, math.radians(-20.0)), (5.6e7 * FT2, math.radians(35.0)))
"""(E m^2/s^2, sigma_ref rad) breakpoints, increasing E; constant outside."""
MACH_FINAL = 2.7
"""Terminal Mach number of the reference (paper: "close to Mach 2.7")."""
EXTENSION = 3e6 * FT2
"""Energy span integrated above the entry energy, m^2/s^2."""
E_LOWEST = 1e6 * FT2
"""Lower end of the downward integration (below the Mach 2.7 energy, about 6.2e6 ft^2/s^2)."""
R_ENTRY = sx2.R_EARTH + sx2.H0
"""Entry radius of the reference, m."""
E_ENTRY = entry.energy(R_ENTRY, sx2.V0)
"""Entry energy of the reference, m^2/s^2 (1.508685e8 ft^2/s^2, extraction Sec. 3.5)."""


def alpha_ref(e):
    """Reference angle of attack (rad) at energy e (m^2/s^2)."""
    es, values = zip(*ALPHA_BREAKS)
    return np.interp(e, es, values)


def sigma_ref(e):
    """Reference bank angle (rad) at energy e (m^2/s^2); positive turns toward +phi."""
    es, values = zip(*SIGMA_BREAKS)
    return np.interp(e, es, values)


def breakpoints():
    """Energies (m^2/s^2) where a reference control has a kink."""
    return sorted({e for e, _ in ALPHA_BREAKS + SIGMA_BREAKS})


def open_loop_derivatives(e, x):
    """dx/dE of x = (r, theta, phi, gamma, chi) flown with the reference controls (eqs. 10-15)."""
    alpha, sigma = alpha_ref(e), sigma_ref(e)
    lift, drag = entry.specific_lift_drag(x[0], e, alpha)
    return entry.energy_derivatives(x, e, lift * np.cos(sigma), lift * np.sin(sigma), drag)


def _mach_at(r, e):
    return entry.mach(r - sx2.R_EARTH, float(entry.speed(r, e)))


def integrate(spacing=2e4 * FT2, rtol=1e-11):
    """The reference on an energy grid, from E0 + EXTENSION down to the Mach 2.7 energy.

    Returns (energies decreasing, states (n, 5), terminal energy). The grid has the given spacing
    (m^2/s^2) plus the control breakpoints and the entry energy; values come from the dense
    output of an RK45 integration in energy (scipy solve_ivp, rtol as given).
    """
    from scipy.integrate import solve_ivp

    x0 = [R_ENTRY, 0.0, 0.0, 0.0, 0.0]
    def mach_event(e, x):
        return _mach_at(x[0], e) - MACH_FINAL

    mach_event.terminal = True  # type: ignore[attr-defined]  # read by solve_ivp
    down = solve_ivp(open_loop_derivatives, (E_ENTRY, E_LOWEST), x0, method="RK45",
                     rtol=rtol, atol=1e-12, dense_output=True, events=mach_event)
    e_final = float(down.t_events[0][0])
    up = solve_ivp(open_loop_derivatives, (E_ENTRY, E_ENTRY + EXTENSION), x0, method="RK45",
                   rtol=rtol, atol=1e-12, dense_output=True)
    grid = np.arange(E_ENTRY + EXTENSION, e_final, -spacing)
    grid = np.unique(np.concatenate([grid, [e_final, E_ENTRY],
                                     [b for b in breakpoints() if e_final < b < grid[0]]]))[::-1]
    states = np.array([up.sol(e) if e > E_ENTRY else down.sol(e) for e in grid])
    return grid, states, e_final
