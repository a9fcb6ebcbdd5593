"""ShuttleAdaptive FMU: seed 003 Slotine-Li modified adaptive elevator law, eqs. (5.28)-(5.35)."""

from aotv_cosim.fmu import guidance_slave
from aotv_cosim.fmu.slave import POSITIVE, AotvSlave
from aotv_cosim.guidance.shuttle_laws import ADAPTIVE_GAINS, AdaptiveLaw
from aotv_cosim.physics import shuttle_trajectory as st
from aotv_cosim.physics.shuttle_pitch import GENERIC

NAMES = ("m", "c", "k", "d", "n")


class ShuttleAdaptive(AotvSlave):
    """delta_e = -Y_m P_hat, P_hat' = -Gamma Y_m^T s, P_hat(xi0) = 0; needs only alpha, alpha'
    and V (for d xi = V dt / L). Defaults: the printed 150,000 ft gains. anti_windup = 1 holds the
    adaptation while delta_e_applied differs from the command (elevator saturated)."""

    description = "Seed 003 Slotine-Li adaptive elevator law (5.28)-(5.35)"
    default_step = 0.02

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        lam, gam = ADAPTIVE_GAINS["150kft"]
        self.parameter("lam", lam, "1", "Sliding-surface gain lambda, per shuttle length")
        for name, g in zip(NAMES, gam):
            self.parameter(f"gamma_{name}", g, "1", f"Adaptation gain of the {name} estimate")
        self.integer_parameter("anti_windup", 0, "1: freeze adaptation while saturated", min=0, max=1)
        self.parameter("L", GENERIC.L, "m", "Shuttle reference length of xi")
        guidance_slave.declare_pitch_measurements(self, ('alpha', 'alpha_prime'))
        self.input("v", st.V_HI, "m/s", "Speed", min=POSITIVE)
        self.input("delta_e_applied", 0.0, "rad", "Elevator deflection actually applied")
        self.output("delta_e", "rad", "Commanded elevator deflection", self._command,
                    depends_on=("alpha", "alpha_prime"))
        for i, name in enumerate(NAMES):
            self.output(f"{name}_hat", "1", f"Estimate of {name} (5.9)",
                        lambda i=i: float(self.law.p_hat[i]))
        self.law = None
        self._new_law()

    def _new_law(self):
        gains = [getattr(self, f"gamma_{n}") for n in NAMES]
        self.law = AdaptiveLaw(self.lam, gains, bool(self.anti_windup))

    def _command(self):
        return self.law.command(self.alpha, self.alpha_prime)

    def start_state(self):
        self._new_law()

    def do_step(self, current_time, step_size):
        saturated = abs(self.delta_e_applied - self._command()) > 1e-12
        self.law.adapt(self.v * step_size / self.L, self.alpha, self.alpha_prime, saturated)
        return True
