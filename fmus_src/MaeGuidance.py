"""MaeGuidance FMU: zeroth-order matched-asymptotic-expansion guidance of seed 001 (Sec. 3.8)."""

import math

from aotv_cosim.fmu import guidance_slave
from aotv_cosim.fmu.slave import POSITIVE, AotvSlave
from aotv_cosim.guidance import mae
from aotv_cosim.guidance.mae_guided import MaeGuidanceLaw
from aotv_cosim.physics import mrrv

STATE = ("r", "v", "gamma", "psi")


class MaeGuidance(AotvSlave):
    """Commands normalized lift lambda and bank mu from the measured r, v, gamma, psi.

    The zeroth-order MAE problem (Calise & Melamed Secs. 3.6-3.7, App. B) is solved from the
    measured state at initialization and re-solved every `update_period` s (Sec. 3.8.2: 5 s),
    warm-started; lambda and mu follow from the held constants at every step, eqs. (3.26)-(3.27)
    with the composite costates (3.105)-(3.110). Exit phase once gamma >= 0 (r_s frozen, extraction
    4.7); a failed re-solve keeps the last converged constants (extraction A19) and is counted.
    Options: measured u in P_u (A17), the experimental first-order HJB correction (Sec. 4), and
    stop_turn_at_psi_f (ours); see aotv_cosim.guidance.mae_guided.
    The atmosphere and vehicle parameters must match the Atmosphere and vehicle FMUs: the solve
    maps density to the inner variable w = K_w rho(r) (eq. 3.43).
    """

    description = "Zeroth-order MAE guidance for the aeroassisted plane change (seed 001 Sec. 3.8)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        guidance_slave.declare_plane_change_problem(self)
        p = self.parameter
        p("psi_f", math.radians(20.0), "rad", "Exit heading target (Sec. 3.7.2: 20 deg change)")
        p("update_period", 5.0, "s", "Time between MAE re-solves (Sec. 3.8.2: 5 s)")
        self.integer_parameter("measured_u_in_p_u", 0,
                               "1: measured u in the inner P_u (extraction A17); 0: u_0^i(psi)", min=0, max=1)
        self.integer_parameter("first_order", 0,
                               "1: first-order HJB costate correction (Sec. 4, experimental)", min=0, max=1)
        self.integer_parameter("stop_turn_at_psi_f", 0,
                               "1: only the vertical lift component once psi >= psi_f (not in the report)",
                               min=0, max=1)
        start = (mrrv.R_EARTH + 60.0e3, 7851.0, math.radians(-1.35), 0.0)
        for name, value, unit, what in zip(STATE, start, ("m", "m/s", "rad", "rad"),
                                           ("radius", "speed", "flight-path angle", "heading")):
            self.input(name, value, unit, f"Measured {what}",
                       **({"min": POSITIVE} if name in ("r", "v") else {}))
        out = self.output
        out("lam", "1", "Normalized lift command lambda (eq. 3.26)", lambda: self._evaluated()[0][0],
            depends_on=STATE)
        out("bank", "rad", "Bank command mu (eq. 3.27)", lambda: self._evaluated()[0][1], depends_on=STATE)
        for i, (name, what) in enumerate([("p_u", "P_u (eqs. 3.105, 3.108)"),
                                          ("p_gamma", "P_gamma (eqs. 3.106, 3.109)"),
                                          ("p_psi", "P_psi = a3 (eq. 3.107)")]):
            out(name, "1", f"Composite costate {what} at the measured state",
                lambda i=i: self._evaluated()[1][i], depends_on=STATE)
        solved = self._solution_output
        solved("solve_time", "s", "Wall-clock time of the last MAE solve", lambda s: s.solve_time)
        solved("converged", "1", "1 if the last MAE solve converged, else 0",
               lambda s: 1.0 if s.converged else 0.0)
        solved("iterations", "1", "Outer Newton iterations of the last MAE solve",
               lambda s: float(s.iterations))
        solved("exit_mode", "1", "1 once the solves are in the exit phase (gamma >= 0), else 0",
               lambda s: 1.0 if s.mode == mae.EXIT else 0.0)
        solved("eps", "1", "Expansion parameter H_s/r_s of the held constants (eq. 3.15)",
               lambda s: s.constants.eps)
        solved("z_s", "m", "Altitude of the reference (lowest) point r_s - R_e (eq. 3.115)",
               lambda s: s.constants.r_s - self.R_e)
        solved("psi_l", "rad", "Left common-part heading psi_L", lambda s: s.constants.psi_l)
        solved("psi_r", "rad", "Right common-part heading psi_R", lambda s: s.constants.psi_r)
        solved("v_f_pred", "m/s", "Composite prediction of the exit speed (eq. 3.100 at h_f)",
               lambda s: s.constants.exit_speed(self.R_e + self.z_f, self.psi_f))
        law = self._law_output
        law("solves", "1", "Number of MAE solves so far", lambda w: float(len(w.solutions)))
        law("failures", "1", "Number of MAE solves that failed (constants kept)",
            lambda w: float(w.failures))
        self.law = None
        self._key = None
        self._evaluation = None

    def _solution_output(self, name, unit, description, getter):
        self.output(name, unit, description, lambda: getter(self._law().solution),
                    initial_depends_on=STATE)

    def _law_output(self, name, unit, description, getter):
        self.output(name, unit, description, lambda: getter(self._law()), initial_depends_on=STATE)

    def _state(self):
        return mae.State(self.r, self.v, self.gamma, self.psi)

    def _new_law(self):
        model = mae.MaeModel(self.E_star, self.CL_star, self.S_ref, self.mass, self.scale_height,
                             self.rho_ref, self.h_ref, self.R_e, self.mu)
        return MaeGuidanceLaw(mae.Targets(self.z_f, self.gamma_f, self.psi_f), model,
                              self.update_period, bool(self.measured_u_in_p_u),
                              bool(self.stop_turn_at_psi_f), bool(self.first_order),
                              next_update=self.start_time)

    def _law(self):
        """The running law; in initialization mode, the one solved for the current inputs."""
        if self.initializing:
            key = tuple(getattr(self, v.name) for v in self.vars.values()
                        if v.causality.name in ("input", "parameter"))
            if key != self._key:
                self.law = self._new_law()
                self.law.update(self.start_time, self._state())
                self._key = key
        return self.law

    def _evaluated(self):
        """((lambda, bank), (P_u, P_gamma, P_psi)) at the measured state, computed once per state
        and held solution: the five outputs read in a step share one evaluation."""
        law, state = self._law(), self._state()
        held = self._evaluation
        if held is None or held[0] is not law.solution or held[1] != law.offset or held[2] != state:
            held = self._evaluation = (law.solution, law.offset, state,
                                       (law.command(state), law.costates(state)))
        return held[3]

    def latch(self):
        self._law()

    def do_step(self, current_time, step_size):
        """Re-solve from the inputs (the state at current_time + step_size) when one is due."""
        self.law.update(current_time + step_size, self._state())
        return True
