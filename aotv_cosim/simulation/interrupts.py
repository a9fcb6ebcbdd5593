"""Deferred SIGINT/SIGTERM: a signal is only recorded, and the run stops at a safe point.

A Python signal handler runs in the main thread at whatever bytecode it is executing, and
pythonfmu runs each FMU's Python code in this interpreter: a handler that raised could land
inside an FMU (turning the interruption into an FMU failure), inside the result writers (a cut
line), or between recording a time and recording its row (one more time than rows). So while
`deferred()` is active the handler raises nothing: it notes the first signal in `RECEIVED`, and
the master's loop looks at `RECEIVED` before each step (one list truth test, so a signal that
lands in FMU code takes effect as soon as that step's calls return), and the runner once more
before it writes the summary. Later signals are ignored so the partial results get written,
except inside `forcible()`: there code may not return to the places that look (FMU code that
hangs in a step, an endless import while an FMU is built or instantiated), so the second signal
(with `first=True`, already the first) raises `Interrupted` in whatever code runs, once.

Outside `deferred()` the command line's handler (`raise_once`) raises KeyboardInterrupt at the
first SIGINT or SIGTERM, so the `finally` blocks of the code it lands in run (a child process is
killed, a temporary folder removed) whichever the signal, and ignores the later ones while they do.
"""

import contextlib
import signal
import threading

SIGNALS = (signal.SIGINT, signal.SIGTERM)

class Interrupted(KeyboardInterrupt):
    """Raised before the next step (the loop) or batch (a campaign) once a SIGINT/SIGTERM was
    recorded, or by `forcible` where the code is. A KeyboardInterrupt, as the user's interruption
    is: no `except Exception` on its way (a loader reporting a corrupt file) takes it for a failure."""


RECEIVED: list[int] = []
"""The number of the first SIGINT/SIGTERM received while deferred (empty if none)."""
FORCED: list[int] = []
"""The number of the signal `forcible` raised as Interrupted (empty if none): a failure the
interrupted code reports afterwards (an FMU's fatal status) is the interruption's."""

_depth = 0
_count = 0
"""Signals received since the outermost `deferred` began."""
_force_at = None
"""Inside `forcible`: the count of signals (1 or 2) at which the handler raises; else None."""


def _record(signum, frame):
    global _count
    if not RECEIVED:
        RECEIVED.append(signum)
    _count += 1
    if _force_at is not None and _count >= _force_at and not FORCED:
        FORCED.append(signum)
        raise Interrupted(signal.Signals(signum).name)


def forced() -> bool:
    """True once `forcible` raised Interrupted for a signal."""
    return bool(FORCED)


@contextlib.contextmanager
def forcible(first: bool = False):
    """Inside, while deferred in the main thread: the second SIGINT/SIGTERM (with `first`, the
    first) raises Interrupted where the main thread is, once: for code that may never reach a
    place that looks at `RECEIVED` (an FMU's step or import that hangs). Outside `deferred`, or in
    another thread, nothing changes. The previous setting is restored on exit."""
    global _force_at
    if _depth == 0 or threading.current_thread() is not threading.main_thread():
        yield
        return
    previous, _force_at = _force_at, (1 if first else 2)
    try:
        if first and RECEIVED and not FORCED:  # a signal already waiting
            FORCED.append(RECEIVED[0])
            raise Interrupted(signal.Signals(RECEIVED[0]).name)
        yield
    finally:
        _force_at = previous


def raise_once(signum, frame):
    """The command line's handler of SIGINT and SIGTERM outside `deferred`: the first records the
    signal and raises KeyboardInterrupt; later ones are ignored, so the cleanup the first set off
    (killing a child process, removing a temporary folder) is not cut short."""
    if RECEIVED:
        return
    RECEIVED.append(signum)
    raise KeyboardInterrupt(signal.Signals(signum).name)


@contextlib.contextmanager
def raising_once():
    """`raise_once` as the SIGINT and SIGTERM handler inside (main thread only; the previous
    handlers are restored)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    RECEIVED.clear()
    previous = {n: signal.signal(n, raise_once) for n in SIGNALS}
    try:
        yield
    finally:
        for number, handler in previous.items():
            if handler is not None:
                signal.signal(number, handler)


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
    global _count
    previous = None
    if _depth == 0:
        RECEIVED.clear()
        FORCED.clear()
        _count = 0
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
