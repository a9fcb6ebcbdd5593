"""A plain pythonfmu3 class (Fmi3Slave, no aotv_cosim base), as an engineer who writes pythonfmu3
classes would give it to `aotv-cosim build-fmus`: a Float64 input and parameter with units, an
Int32 output, Boolean and String parameters, two Float64 outputs. y = k u (0 when `on` is false),
z integrates y, n counts the steps; a step with u < 0 is refused (do_step returns False)."""

from pathlib import Path

SOURCE = '''
from pythonfmu3 import Boolean, Fmi3Causality, Fmi3Slave, Fmi3Status, Fmi3Variability, Float64, Int32, String


class Gain3(Fmi3Slave):
    """y = k u, integrated into z; n counts the steps."""

    description = "Gain y = k u, integrated into z"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.u, self.k, self.y, self.z, self.n, self.on, self.label = 0.5, 0.1, 0.0, 0.0, 0, True, "gain"
        continuous, fixed = Fmi3Variability.continuous, Fmi3Variability.fixed
        self.register_variable(Float64("u", causality=Fmi3Causality.input, variability=continuous, unit="m/s"))
        self.register_variable(Float64("k", causality=Fmi3Causality.parameter, variability=fixed, unit="1"))
        self.register_variable(Int32("n", causality=Fmi3Causality.output, variability=Fmi3Variability.discrete))
        self.register_variable(Boolean("on", causality=Fmi3Causality.parameter, variability=fixed))
        self.register_variable(String("label", causality=Fmi3Causality.parameter, variability=fixed))
        self.register_variable(Float64("y", causality=Fmi3Causality.output, variability=continuous, unit="m/s"))
        self.register_variable(Float64("z", causality=Fmi3Causality.output, variability=continuous, unit="m"))

    def do_step(self, current_time, step_size):
        if self.u < 0:
            self.log(f"{self.label}: u = {self.u} < 0, step refused", Fmi3Status.error)
            return False
        self.y = self.k * self.u if self.on else 0.0
        self.z += self.y * step_size
        self.n += 1
        return True
'''
"""The class's source (module docstring)."""


def write_gain3(folder: Path) -> Path:
    """The source written as folder/Gain3.py."""
    path = Path(folder) / "Gain3.py"
    path.write_text(SOURCE)
    return path
