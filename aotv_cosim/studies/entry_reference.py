"""Generate the seed 002 reference table: `python -m aotv_cosim.studies.entry_reference [--out PATH]`.

Integrates the reference controls of `physics.entry_reference` open loop in energy and writes the
table the tracking guidance reads (`guidance.entry_tracking_reference.TABLE` by default), then
prints the terminal state in the paper's units.
"""

import argparse
import math

from aotv_cosim.guidance import entry_tracking_reference as table
from aotv_cosim.physics import entry, entry_reference, sx2

SPACING = 1e5 * entry_reference.FT2
"""Row spacing of the checked-in table, m^2/s^2 (Hermite interpolation keeps it accurate)."""


def generate(path=table.TABLE, spacing=SPACING):
    """Write the table to path; returns (energies, states, terminal energy)."""
    energies, states, e_final = entry_reference.integrate(spacing)
    table.write_table(path, energies, states, entry_reference.alpha_ref(energies),
                      entry_reference.sigma_ref(energies), sx2.R_EARTH)
    return energies, states, e_final


def summary(states, e_final) -> str:
    """The terminal state of the reference in ft, ft/s, deg and n mi."""
    r, theta, phi, gamma, chi = states[-1]
    h, v = r - sx2.R_EARTH, float(entry.speed(r, e_final))
    return (f"E_f = {e_final:.6e} m^2/s^2 ({e_final / entry_reference.FT2:.6e} ft^2/s^2), "
            f"h = {h / sx2.FT:.0f} ft, V = {v / sx2.FT:.1f} ft/s, Mach {entry.mach(h, v):.3f}, "
            f"gamma = {math.degrees(gamma):.2f} deg, chi = {math.degrees(chi):.2f} deg, "
            f"downrange {sx2.R_EARTH * theta / sx2.NMI:.1f} n mi, "
            f"crossrange {sx2.R_EARTH * phi / sx2.NMI:.1f} n mi")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(table.TABLE), help="table path (default: the bundled one)")
    args = parser.parse_args(argv)
    energies, states, e_final = generate(args.out)
    print(f"wrote {args.out}: {len(energies)} rows; {summary(states, e_final)}")


if __name__ == "__main__":
    main()
