"""Robust linear feedback of seed 000, Ch. 7, eqs. (7.1)-(7.5).

du = -kappa_r dr - kappa_v dv - kappa_gamma dgamma (7.1), errors actual - model, applied as
u = u_m(t) + du (the missing eq. 7.2, extraction Sec. 8 item 16). The gains are used literally in
km-s units: kappa_r in 1/s^2, kappa_v in 1/s, kappa_gamma = 0.526 v_m in km/s^2 per rad with the
model speed v_m in km/s. (kappa_r and kappa_v make the law unit-invariant; kappa_gamma does too
because v_m carries the length unit.)
"""

KAPPA_R = 1.086957e-4
"""Radius-error gain of eq. (7.3), 1/s^2."""
KAPPA_V = 6.082725e-2
"""Speed-error gain of eq. (7.4), 1/s."""
KAPPA_GAMMA_PER_SPEED = 0.526
"""Factor of eq. (7.5), kappa_gamma = 0.526 v_m, in 1/s."""


def robust_delta_u(state_si, model_si) -> float:
    """Correction du of eqs. (7.1)-(7.5) in m/s^2.

    state_si: actual (h m, v m/s, gamma rad); model_si: model/nominal state at the same time, whose
    speed is v_m of (7.5). Plain float arithmetic, as `planar.km_error` forms the errors (once per
    guidance step, where numpy's per-call cost on 3-element arrays would dominate).
    """
    (h, v, gamma), (h_m, v_m, gamma_m) = state_si, model_si
    dr, dv, dgamma = (h - h_m) * 1e-3, (v - v_m) * 1e-3, gamma - gamma_m
    kappa_gamma = KAPPA_GAMMA_PER_SPEED * v_m * 1e-3
    return float(-(KAPPA_R * dr + KAPPA_V * dv + kappa_gamma * dgamma) * 1e3)
