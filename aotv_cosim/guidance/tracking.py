"""Feedback laws of seed 000 that track a nominal trajectory: u = u_d(t) + du(x, t).

The nominal (desired) trajectory is the minimum-effort optimum of the 2PBVP (3.21)-(3.22) from a
design entry (Table 4.1 by default), `optimal_bvp.solve_min_effort`; "existing scheme: optimal
trajectory plus robust control", Fig. 9.2. Each law is a small object with the same interface,
used alike by the guidance FMUs, the monolithic reference and the comparison study:

- `delta_u(t, state)`: the correction du (m/s^2) at t (s since entry) for the measured state
  (h m, v m/s, gamma rad);
- `advance(t, dt, state)`: move the law's own state (only the adaptive law has one) over a step.

Laws: infinite-horizon LQR (5.5)-(5.9), terminal-time LQR (5.10)-(5.18), robust feedback
(7.1)-(7.5) and the adaptive PD law (8.5)-(8.9). All SI at this interface; km-s inside, as the
thesis's gains and weights are in km and s (see the law modules).
"""

from dataclasses import dataclass, field

import numpy as np

from aotv_cosim.guidance import adaptive, lqr, robust
from aotv_cosim.guidance.optimal_bvp import MinEffortSolution


def desired_state(nominal: MinEffortSolution, t: float, r_earth: float) -> tuple:
    """Nominal (h m, v m/s, gamma rad) at one time t (s), floats, from the 2PBVP solution; r_earth
    in m."""
    r, v, gamma = nominal.state_at(t)
    return r - r_earth, v, gamma


@dataclass
class InfiniteLqrLaw:
    """du = -k^T dx, eqs. (5.7)-(5.9), gain from (A, B) frozen at t = 0 on the nominal (5.2)/(5.3).

    q: diagonal of Q, r: R, both in the km-s units of (5.6) (defaults: the (5.6) design).
    """

    nominal: MinEffortSolution
    r_earth: float
    k_ball: float
    q: tuple = tuple(np.diag(lqr.Q_INFINITE))
    r: float = lqr.R_INFINITE
    gain: np.ndarray = field(init=False)

    def __post_init__(self):
        a_mat, b_vec = lqr.frozen_linearization(desired_state(self.nominal, 0.0, self.r_earth),
                                                float(self.nominal.u(0.0)), self.k_ball)
        self.gain = lqr.infinite_horizon_gain(a_mat, b_vec, np.diag(self.q), self.r)

    def delta_u(self, t, state):
        return lqr.feedback(self.gain, state, desired_state(self.nominal, t, self.r_earth))

    def advance(self, t, dt, state):
        """No internal state."""


@dataclass
class TerminalLqrLaw:
    """du = -k(t)^T dx, eqs. (5.12)-(5.18) on [0, tf], M0(tf) = V, (A, B) frozen at t = 0.

    q, v_term: diagonals of Q and V, r: R, km-s units (defaults: the (5.11) design).
    """

    nominal: MinEffortSolution
    r_earth: float
    k_ball: float
    tf: float
    q: tuple = tuple(np.diag(lqr.Q_TERMINAL))
    r: float = lqr.R_TERMINAL
    v_term: tuple = tuple(np.diag(lqr.V_TERMINAL))
    frozen: tuple[np.ndarray, np.ndarray] = field(init=False)

    def __post_init__(self):
        self.frozen = lqr.frozen_linearization(desired_state(self.nominal, 0.0, self.r_earth),
                                               float(self.nominal.u(0.0)), self.k_ball)

    _last: tuple = field(init=False, default=(None, None))

    def gain(self, t):
        """k(t) of (5.13), km-s, shape (3,); the last one is kept (u and du read it at one t)."""
        if self._last[0] != t:
            k = lqr.terminal_gain_schedule(*self.frozen, [min(t, self.tf)], self.tf, np.diag(self.q),
                                           self.r, np.diag(self.v_term))[0]
            self._last = (t, k)
        return self._last[1]

    def delta_u(self, t, state):
        return lqr.feedback(self.gain(t), state, desired_state(self.nominal, t, self.r_earth))

    def advance(self, t, dt, state):
        """No internal state."""


@dataclass
class RobustLaw:
    """du of eqs. (7.1)-(7.5) about the nominal (the model trajectory of Ch. 7)."""

    nominal: MinEffortSolution
    r_earth: float

    def delta_u(self, t, state):
        return robust.robust_delta_u(state, desired_state(self.nominal, t, self.r_earth))

    def advance(self, t, dt, state):
        """No internal state."""


@dataclass
class AdaptiveLaw:
    """du of eq. (8.8) with Theta integrated by explicit Euler of (8.9) over each step.

    Theta starts at Theta0 of Sec. 8.2.2; k_ball is the model's K used in A of (5.2).
    """

    MUTABLE_STATE = True
    """`advance` replaces theta: an FMU's saved state holds a copy of this object (fmu/slave.py)."""

    nominal: MinEffortSolution
    r_earth: float
    k_ball: float
    theta: np.ndarray = field(default_factory=lambda: adaptive.THETA0.copy())

    def _evaluate(self, t, state):
        desired = desired_state(self.nominal, t, self.r_earth)
        return adaptive.adaptive_step(self.theta, state, desired, self.nominal.u_at(t), self.k_ball)

    def delta_u(self, t, state):
        return self._evaluate(t, state)[0]

    def advance(self, t, dt, state):
        """Theta <- Theta + dt dTheta/dt (8.9), the rate taken at the step's start (t, state)."""
        self.theta = self.theta + dt * self._evaluate(t, state)[1]
