"""The Signaller test FMU: signals its own process from inside do_step, optionally slowly."""

import textwrap

SIGNALLER_SOURCE = textwrap.dedent('''
    import os
    import time

    from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real


    class Signaller(Fmi2Slave):
        """Test FMU: y = t; in the step starting at signal_time (s) it sends signal signum to its
        own process; every step sleeps busy seconds (FMU code that takes time)."""

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.signal_time = -1.0
            self.signum = 15.0
            self.busy = 0.0
            self.y = 0.0
            for name in ("signal_time", "signum", "busy"):
                self.register_variable(Real(name, causality=Fmi2Causality.parameter,
                                            variability=Fmi2Variability.fixed))
            self.register_variable(Real("y", causality=Fmi2Causality.output))

        def do_step(self, current_time, step_size):
            if self.busy:
                time.sleep(self.busy)
            if abs(current_time - self.signal_time) < 0.5 * step_size:
                os.kill(os.getpid(), int(self.signum))
                sum(k * k for k in range(20000))  # still in FMU code when the handler runs
            self.y = current_time + step_size
            return True
''')


def build_signaller(folder):
    """Build Signaller.fmu in `folder`; returns its path."""
    from pythonfmu.builder import FmuBuilder

    (folder / "Signaller.py").write_text(SIGNALLER_SOURCE)
    return FmuBuilder.build_FMU(folder / "Signaller.py", dest=folder / "Signaller.fmu")
