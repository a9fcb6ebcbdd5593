"""Deferred SIGINT/SIGTERM: a signal is only recorded, and the run stops at a safe point.

A Python signal handler runs in the main thread at whatever bytecode it is executing, and
pythonfmu runs each FMU's Python code in this interpreter: a handler that raised could land
inside an FMU (turning the interruption into an FMU failure), inside the result writers (a cut
line), or between recording a time and recording its row (one more time than rows). So while
`deferred()` is active the handler raises nothing: it notes the first signal in `RECEIVED`, and
the master's loop looks at `RECEIVED` before each step (one list truth test, so a signal that
lands in FMU code takes effect as soon as that step's calls return), and the runner once more
before it writes the summary. Later signals are ignored so the partial results get written.
"""

import contextlib
import signal
import threading

SIGNALS = (signal.SIGINT, signal.SIGTERM)

class Interrupted(Exception):
    """Raised before the next step (the loop) or batch (a campaign) once a SIGINT/SIGTERM was
    recorded."""


RECEIVED = []
"""The number of the first SIGINT/SIGTERM received while deferred (empty if none)."""

_depth = 0


def _record(signum, frame):
    if not RECEIVED:
        RECEIVED.append(signum)


def received():
    """The first signal number received while deferred, else None."""
    return RECEIVED[0] if RECEIVED else None


def name():
    """'SIGINT' or 'SIGTERM': the signal received (None if none)."""
    return signal.Signals(RECEIVED[0]).name if RECEIVED else None


@contextlib.contextmanager
def deferred():
    """Record SIGINT/SIGTERM instead of acting on them, for the outermost `with` in the main thread.

    The outermost entry forgets any earlier signal and installs the recording handler; its exit
    restores the previous handlers. Nested entries and other threads change nothing (Python runs
    signal handlers in the main thread only)."""
    global _depth
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = None
    if _depth == 0:
        RECEIVED.clear()
        previous = {n: signal.signal(n, _record) for n in SIGNALS}
    _depth += 1
    try:
        yield
    finally:
        _depth -= 1
        if previous is not None:
            for number, handler in previous.items():
                if handler is not None:  # None: installed outside Python, cannot be put back
                    signal.signal(number, handler)
