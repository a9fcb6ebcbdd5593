"""EntryTrackingGuidance FMU: seed 002 ground-track tracking by feedback linearization (eqs. 33-54)."""

import math
from functools import cache

import numpy as np

from aotv_cosim.fmu.slave import POSITIVE, AotvSlave
from aotv_cosim.guidance import entry_tracking as law
from aotv_cosim.guidance.entry_tracking_reference import Reference
from aotv_cosim.physics import entry, sx2

STATE = ("r", "theta", "phi", "v", "gamma", "psi")
STATE_RANGES = {"r": {"min": POSITIVE}, "v": {"min": POSITIVE}}
"""Declared ranges of the measured state (the law divides by r and v)."""


@cache
def shared_reference():
    """The bundled reference table, read once per process (read only: every instance shares it).
    A host may extract this FMU again for another system and delete the first folder, which the
    module stays imported from."""
    return Reference()


class EntryTrackingGuidance(AotvSlave):
    """Commands alpha and bank from the measured state so that theta(E), phi(E) track the reference.

    The law, its gains (poles in the energy domain) and the constrained inversion are
    `aotv_cosim.guidance.entry_tracking`; the reference is the bundled table of
    `guidance.entry_tracking_reference`, looked up at the measured energy. The integral terms
    int_{E0}^{E} e dE are trapezoids between communication points, committed in do_step (E0 is the
    energy when initialization ends). Outputs feed through from the state inputs.
    """

    description = "Seed 002 entry tracking law: feedback linearization in energy, alpha and bank commands"
    default_step = 0.1
    default_stop = 900.0

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        deg = math.radians(1.0)
        p = self.parameter
        p("omega1", 33.6, "1", "Downrange pole frequency, units of 1/(mu/r0) (energy domain)")
        p("zeta1", 0.7, "1", "Downrange pole damping")
        p("omega2", 33.6, "1", "Crossrange pole frequency, units of 1/(mu/r0) (energy domain)")
        p("zeta2", 0.7, "1", "Crossrange pole damping")
        self.integer_parameter("integral_terms", 1, "1: include the integral feedback of eq. (49); 0: omit",
                               min=0, max=1)
        self.integer_parameter("inversion", 0, "Control recovery: 0 the paper's (52-54) with D = D~; 1 exact in "
                                               "the drag at the commanded alpha (entry_tracking.drag_aware_controls)",
                               min=0, max=1)
        p("eta", 0.5, "1", "Downrange weight of the constrained inversion, eq. (54)")
        p("alpha_width", 5.0 * deg, "rad", "Half-width of the alpha band around alpha_ref")
        p("alpha_min", 5.0 * deg, "rad", "Lowest alpha (validity of the polar fit)")
        p("alpha_max", 25.0 * deg, "rad", "Highest alpha (validity of the polar fit)")
        p("sigma_width", 90.0 * deg, "rad", "Half-width of the bank band around sigma_ref")
        p("sigma_max", 80.0 * deg, "rad", "Largest |bank|")
        p("R0", sx2.R_EARTH, "m", "Radius converting angle errors to distances (paper: r0)")
        entry_state = (sx2.R_EARTH + sx2.H0, 0.0, 0.0, sx2.V0, 0.0, 0.0)  # start values: the paper's entry
        for name, unit, start in zip(STATE, ("m", "rad", "rad", "m/s", "rad", "rad"), entry_state):
            self.input(name, start, unit, f"Measured {name}", **STATE_RANGES.get(name, {}))
        self.reference = shared_reference()
        self.integrals = np.zeros(2)
        self.anchor = None
        self._key = None
        self._out = None
        deps = STATE
        outputs = (
            ("alpha_cmd", "rad", "Commanded angle of attack"),
            ("sigma_cmd", "rad", "Commanded bank angle (positive turns toward +phi)"),
            ("alpha_ref", "rad", "Reference angle of attack at the measured energy"),
            ("sigma_ref", "rad", "Reference bank angle at the measured energy"),
            ("alpha_low", "rad", "Lower alpha band"), ("alpha_high", "rad", "Upper alpha band"),
            ("sigma_low", "rad", "Lower bank band"), ("sigma_high", "rad", "Upper bank band"),
            ("constrained", "1", "1 while the constrained inversion (54) sets the commands"),
            ("energy", "m2/s2", "Specific energy E = v^2/2 - mu/r + mu/r0 (eq. 9)"),
            ("downrange_error", "m", "R0 (theta - theta_ref(E)) (Fig. 2)"),
            ("crossrange_error", "m", "R0 (phi - phi_ref(E)) (Fig. 2)"),
            ("downrange_ref", "m", "R0 theta_ref(E)"), ("crossrange_ref", "m", "R0 phi_ref(E)"),
            ("h_ref", "m", "Reference altitude at the measured energy"),
            ("mach_ref", "1", "Reference Mach number at the measured energy (US76 speed of sound)"),
            ("drag_ref", "m/s2", "Reference drag acceleration at the measured energy"),
        )
        for name, unit, text in outputs:
            self.output(name, unit, text, (lambda n: lambda: self._values()[n])(name), depends_on=deps)

    def _state(self):
        return np.array([self.r, self.theta, self.phi, self.gamma, self.psi]), \
            float(entry.energy(self.r, self.v))

    def _errors(self, x, e):
        x_ref = self.reference.state(e)
        return x[1:3] - x_ref[1:3]

    def _current_integrals(self, x, e):
        if self.anchor is None or not self.integral_terms:
            return np.zeros(2)
        e_last, err_last = self.anchor
        return self.integrals + 0.5 * (err_last + self._errors(x, e)) * (e - e_last)

    def _values(self):
        """Every output by name, computed once per `revision` (17 outputs read them)."""
        if self._key == self.revision:
            return self._out
        x, e = self._state()
        x_ref = self.reference.state(e)
        alpha_ref, sigma_ref = self.reference.controls(e)
        gains = law.gains(self.omega1, self.zeta1, self.omega2, self.zeta2)
        bands = law.Bands(self.alpha_width, self.alpha_min, self.alpha_max, self.sigma_width, self.sigma_max)
        cmd = law.command(x, e, x_ref, alpha_ref, sigma_ref, self._current_integrals(x, e), gains, bands,
                          self.eta, law.INVERSIONS[self.inversion])
        lift, drag = entry.specific_lift_drag(x_ref[0], e, alpha_ref)
        h_ref = x_ref[0] - sx2.R_EARTH
        self._out = {
            "alpha_cmd": cmd.alpha, "sigma_cmd": cmd.sigma, "alpha_ref": alpha_ref, "sigma_ref": sigma_ref,
            "alpha_low": cmd.alpha_band[0], "alpha_high": cmd.alpha_band[1],
            "sigma_low": cmd.sigma_band[0], "sigma_high": cmd.sigma_band[1],
            "constrained": float(cmd.constrained), "energy": e,
            "downrange_error": self.R0 * (x[1] - x_ref[1]), "crossrange_error": self.R0 * (x[2] - x_ref[2]),
            "downrange_ref": self.R0 * x_ref[1], "crossrange_ref": self.R0 * x_ref[2],
            "h_ref": h_ref, "mach_ref": entry.mach(h_ref, float(entry.speed(x_ref[0], e))),
            "drag_ref": float(drag),
        }
        self._key = self.revision
        return self._out

    def _commit(self):
        x, e = self._state()
        self.integrals = self._current_integrals(x, e)
        self.anchor = (e, self._errors(x, e))

    def start_state(self):
        """No integral yet; the commands are recomputed (the gains and bands may have changed)."""
        self.integrals, self.anchor, self._key = np.zeros(2), None, None

    def latch(self):
        self._commit()
        self._key = None

    def do_step(self, current_time, step_size):
        self._commit()
        self._key = None
        return True
