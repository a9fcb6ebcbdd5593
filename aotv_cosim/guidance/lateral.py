"""Lateral logic of bank-angle guidance: the sign of the bank from a plane-error deadband.

A bank-modulated vehicle controls its in-plane motion by the magnitude |sigma| (the vertical lift
L cos sigma) and turns out of plane by the sign of sigma (the horizontal lift L sin sigma turns
the heading psi toward +psi for sigma > 0). The classical logic (Apollo; FNPAG, Lu et al. 2015):
keep the sign while the plane error stays inside a deadband, and reverse the bank when the error
leaves it on the side the current bank drives it to.

Plane error: the target plane is the entry plane, the equator of the vehicle frame (phi = psi = 0
at entry). For small angles the orbit normal's tilt from the target normal has two components,
phi along the local vertical and psi along the local east; the inclination
i = arccos(cos phi cos psi) ~ sqrt(phi^2 + psi^2) (seed 001 Sec. 3.1) is its length. The bank turns
only psi (psi_dot = L sin sigma / (m v cos gamma)), and psi drives phi (phi_dot = v cos gamma sin psi
/ r). The signed error the logic keeps inside the deadband is their sum, e = psi + phi: the
switching line psi = -phi, on which phi decays with the time constant r/v (about 13 min), so that
the latitude error is brought back instead of building up while psi alone stays small. A plane
error signed by i alone would flip with psi while i is held above the deadband by phi, which no
bank can reduce at once (the reversals would then chatter).
"""


def plane_error(phi: float, psi: float) -> float:
    """Signed plane error e = psi + phi (rad; latitude phi and heading psi in rad, module
    docstring): positive when the vehicle is or turns north of the entry plane."""
    return psi + phi


def bank_sign(previous: int, error: float, deadband: float) -> int:
    """Sign (+1 or -1) of the next bank command: `previous` unless |error| > deadband (rad) and
    the previous sign drives the error further out (same sign as the error), then reversed."""
    previous = 1 if previous >= 0 else -1
    if abs(error) > deadband and previous * error > 0.0:
        return -previous
    return previous
