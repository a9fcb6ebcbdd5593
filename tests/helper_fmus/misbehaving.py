"""The Misbehaving test FMU: a pass-through y = u that, from time `at`, hangs, crashes its process or
grows its memory without bound, as user code can.

kind: 0 behaves; 1 hangs in Python (a busy loop); 2 hangs where no signal reaches it (SIGALRM
blocked, then a sleep: like native code that never returns to the interpreter); 3 dereferences
NULL (SIGSEGV); 4 aborts (SIGABRT); 5 allocates and touches 64 MiB per step (and takes 50 ms) until stopped; 6 hangs
in a sleep. kind -1 chooses by `choice` (a draw in [0, 1), so a campaign's seed decides):
[0, 0.05) 1, [0.05, 0.10) 2, [0.10, 0.125) 3, [0.125, 0.15) 4, [0.15, 0.20) 5, else 0: 10 % hang,
5 % crash, 5 % exceed a memory limit.
"""

import textwrap

SOURCE = textwrap.dedent('''
    import ctypes
    import os
    import signal
    import time

    from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real

    BOUNDS = ((0.05, 1), (0.10, 2), (0.125, 3), (0.15, 4), (0.20, 5))


    def chosen(kind, choice):
        if kind >= 0:
            return int(kind)
        return next((k for bound, k in BOUNDS if choice < bound), 0)


    class Misbehaving(Fmi2Slave):
        """Test FMU: y = u; misbehaves from time `at` as `kind` says (tests/misbehaving.py)."""

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            self.kind = 0.0
            self.choice = 1.0
            self.at = 0.5
            self.u = 0.0
            self.y = 0.0
            self.hoard = []
            for name in ("kind", "choice", "at"):
                self.register_variable(Real(name, causality=Fmi2Causality.parameter,
                                            variability=Fmi2Variability.fixed))
            self.register_variable(Real("u", causality=Fmi2Causality.input))
            self.register_variable(Real("y", causality=Fmi2Causality.output))

        def do_step(self, current_time, step_size):
            self.y = self.u
            if current_time + 0.5 * step_size < self.at:
                return True
            kind = chosen(self.kind, self.choice)
            if kind == 1:
                while True:
                    pass
            if kind == 2:
                signal.pthread_sigmask(signal.SIG_BLOCK, [signal.SIGALRM])
                time.sleep(3600)
            if kind == 3:
                ctypes.string_at(0)
            if kind == 4:
                os.abort()
            if kind == 5:
                self.hoard.append(bytearray(b"x") * (64 << 20))
                time.sleep(0.05)
            if kind == 6:
                time.sleep(3600)
            return True
''')


def build_misbehaving(folder):
    """Build Misbehaving.fmu in `folder`; returns its path."""
    from pythonfmu.builder import FmuBuilder

    (folder / "Misbehaving.py").write_text(SOURCE)
    return FmuBuilder.build_FMU(folder / "Misbehaving.py", dest=folder / "Misbehaving.fmu")
