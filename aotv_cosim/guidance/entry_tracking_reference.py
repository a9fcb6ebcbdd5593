"""The seed 002 reference trajectory table: written by `python -m aotv_cosim.studies.entry_reference`, read
by the tracking guidance (bundled into its FMU next to this module).

Columns (SI): energy E (m^2/s^2, decreasing, last row = terminal energy E_f), the guidance state
r, theta, phi, gamma, chi (m, rad), the reference controls alpha, sigma (rad), and for readers and
plots h (m), v (m/s), mach, drag (m/s^2). Between rows the state is a cubic Hermite interpolant
whose node slopes are the energy-domain equations (seed 002 eqs. 10-15) evaluated at the node, so
the table is accurate to O(dE^4) without being dense; the controls are piecewise linear in E with
their breakpoints on the grid, so linear interpolation returns them exactly.
"""

import csv
from pathlib import Path

import numpy as np

from aotv_cosim.physics import entry

TABLE = Path(__file__).with_name("entry_tracking_sx2_reference.csv")
"""The checked-in SX-2 reference table."""
COLUMNS = ("energy", "r", "theta", "phi", "gamma", "chi", "alpha", "sigma", "h", "v", "mach", "drag")
STATE = slice(1, 6)


def write_table(path, energies, states, alphas, sigmas, r_earth):
    """Write the table: energies (m^2/s^2), states (n, 5), controls (rad), planet radius (m)."""
    with open(path, "w", newline="") as stream:
        writer = csv.writer(stream, lineterminator="\n")
        writer.writerow(COLUMNS)
        for e, x, a, s in zip(energies, states, alphas, sigmas):
            _lift, drag = entry.specific_lift_drag(x[0], e, a)
            h, v = x[0] - r_earth, float(entry.speed(x[0], e))
            row = (e, *x, a, s, h, v, entry.mach(h, v), drag)
            writer.writerow([f"{value:.17g}" for value in row])


def read_table(path=TABLE):
    """{column: numpy array} of a reference table, rows in the file's (decreasing E) order."""
    with open(path, newline="") as stream:
        rows = list(csv.reader(stream))
    if tuple(rows[0]) != COLUMNS:
        raise ValueError(f"{path}: columns {rows[0]} are not {list(COLUMNS)}")
    data = np.array(rows[1:], dtype=float)
    return {name: data[:, k] for k, name in enumerate(COLUMNS)}


class Reference:
    """x_ref(E) and u_ref(E) of a table; E in m^2/s^2, clamped to the table's energy range."""

    def __init__(self, path=TABLE):
        from scipy.interpolate import CubicHermiteSpline

        table = read_table(path)
        order = np.argsort(table["energy"])
        self.table = table
        self.energy = table["energy"][order]
        states = np.column_stack([table[c] for c in COLUMNS[STATE]])[order]
        self.alpha, self.sigma = table["alpha"][order], table["sigma"][order]
        lift, drag = entry.specific_lift_drag(states[:, 0], self.energy, self.alpha)
        slopes = np.array(entry.energy_derivatives(states.T, self.energy, lift * np.cos(self.sigma),
                                                   lift * np.sin(self.sigma), drag)).T
        self._spline = CubicHermiteSpline(self.energy, states, slopes)
        self.e_final, self.e_top = self.energy[0], self.energy[-1]

    def clamp(self, e):
        """e limited to the table's energy range."""
        return min(max(e, self.e_final), self.e_top)

    def state(self, e):
        """Reference (r, theta, phi, gamma, chi) at energy e, numpy array."""
        return self._spline(self.clamp(e))

    def controls(self, e):
        """Reference (alpha, sigma) in rad at energy e."""
        e = self.clamp(e)
        return float(np.interp(e, self.energy, self.alpha)), float(np.interp(e, self.energy, self.sigma))
