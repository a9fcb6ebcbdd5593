"""Zeroth-order MAE feedback guidance: periodic re-solves and the per-step control law.

Calise & Melamed, NASA CR-194523 (1993), Sec. 3.8.1 as read in the seed-001 extraction (4.7,
A16-A19): the zeroth-order MAE problem (`mae.solve`) is re-solved every `period` seconds (5 s in
Sec. 3.8.2) from the measured state, warm-started from the previous solution; between re-solves
the held constants give the composite costates at the measured state and lambda, mu follow from
(3.26)-(3.27) at every evaluation (`mae_solution.composite_costates`, `mae_solution.control_from_costates`). The
exit phase starts when the measured gamma >= 0 (r_s frozen, left outer solution dropped); a
failed re-solve keeps the last converged constants (A19).

Option `first_order` (experimental, Sec. 4.3): at each converged re-solve the costates are replaced
by the gradient of the first-order return function (`mae_first_order`); the difference to the
zeroth-order composite costates at that state is held and added at every evaluation until the
next re-solve (the report computed this correction but did not fly it).

One option goes beyond the report (off by default): `stop_turn_at_psi_f` flies only the vertical
lift component delta = lambda cos mu (bank 0 or pi) once the measured heading has reached psi_f.
In the terminal phase the exit-mode MAE has no solution (A19) and the held constants keep
turning the vehicle past psi_f, and turning costs speed: dV/dpsi is about V/E* (~50 m/s per deg).
"""

import math
from dataclasses import dataclass, field

from aotv_cosim.guidance import mae, mae_first_order, mae_solution

TIME_TOL = 1e-9
"""Relative slack (of the period) when deciding whether a re-solve is due, so that float sums of
communication steps land on the 5 s grid."""


@dataclass
class MaeGuidanceLaw:
    """State of the feedback law: the last solution, the next re-solve time and a solve log.

    targets: exit conditions; period: time between re-solves (s); measured_u_in_p_u: extraction
    A17 option of `mae_solution.composite_costates`; stop_turn_at_psi_f: see the module docstring.
    solutions logs every solve as (time s, measured `mae.State`, `mae.MaeSolution`).
    """

    targets: mae.Targets
    model: mae.MaeModel = mae.MaeModel()
    period: float = 5.0
    measured_u_in_p_u: bool = False
    stop_turn_at_psi_f: bool = False
    first_order: bool = False
    offset: tuple = (0.0, 0.0, 0.0)
    solution: "mae.MaeSolution | None" = None
    next_update: float = 0.0
    solutions: list = field(default_factory=list)

    def update(self, t: float, state: mae.State) -> bool:
        """Re-solve from `state` (r m, v m/s, gamma, psi rad) if one is due at time t (s).

        Returns True when a solve was attempted. The first solve raises RuntimeError if it fails
        (there are no constants to keep, `mae.solve`).
        """
        if self.solution is not None and t < self.next_update - TIME_TOL * self.period:
            return False
        self.solution = mae.solve(state, self.targets, self.solution, self.model)
        self.solutions.append((t, state, self.solution))
        if self.first_order and self.solution.converged:
            self.offset = self._first_order_offset(state)
        while self.next_update <= t + TIME_TOL * self.period:
            self.next_update += self.period
        return True

    def _first_order_offset(self, state: mae.State):
        """First-order minus zeroth-order composite costates at `state` (zeros if a solve fails)."""
        assert self.solution is not None  # called after a solve
        first = mae_first_order.first_order_costates(self.solution, state, self.targets, self.model)
        if first is None:
            return (0.0, 0.0, 0.0)
        return tuple(a - b for a, b in zip(first, self._zeroth_costates(state)))

    def _zeroth_costates(self, state: mae.State):
        assert self.solution is not None  # the first `update` solves before any command
        return mae_solution.composite_costates(self.solution.constants, state.r, state.v, state.gamma,
                                      state.psi, self.measured_u_in_p_u)[1:]

    def command(self, state: mae.State):
        """(lambda, bank mu in rad) from the held constants at the measured state (3.26)-(3.27)."""
        assert self.solution is not None  # the first `update` solves before any command
        u = state.v * state.v / self.solution.constants.gs_rs
        p_u, p_gamma, p_psi = self.costates(state)
        lam, bank = mae_solution.control_from_costates(u, state.gamma, p_u, p_gamma, p_psi,
                                                       self.solution.constants.e_star)
        lam, bank = float(lam), float(bank)
        if self.stop_turn_at_psi_f and state.psi >= self.targets.psi_f:
            delta = lam * math.cos(bank)
            return abs(delta), (0.0 if delta >= 0.0 else math.pi)
        return lam, bank

    def costates(self, state: mae.State):
        """(P_u, P_gamma, P_psi) flown at the measured state: the composite costates of the held
        constants (3.105)-(3.110), plus the held first-order offset when `first_order` is on."""
        return tuple(p + d for p, d in zip(self._zeroth_costates(state), self.offset))

    @property
    def failures(self) -> int:
        """Number of re-solves that did not converge (their constants were not used)."""
        return sum(1 for _, _, s in self.solutions if not s.converged)
