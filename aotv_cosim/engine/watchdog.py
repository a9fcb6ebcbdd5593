"""The step watchdog: a communication step that does not end within its wall-clock limit fails the run.

FMUs run in the master's own interpreter (FMPy calls the FMU's C entry points; a pythonfmu FMU's
`do_step` is Python run by this interpreter). A step that hangs is ended in one of two ways:

- Python code that hangs (a loop, a sleep, a wait on a lock or a socket) is interrupted in the
  process: `limited` arms a one-shot `ITIMER_REAL` before each step, and its SIGALRM handler raises
  `StepLimitReached` in whatever the main thread is running. Inside an FMU's `do_step` pythonfmu reports the
  exception as fmi2Fatal, the master raises its `SimulationError` naming that component, and
  `limited` turns it into `StepTimeout` ("step timeout: fmi2DoStep of COMP did not return within
  N s at t = T s"): the run is `failed`, its rows up to t kept. A blocking system call is
  interrupted too (Python retries it only after the handler, which raises).
- Native code that never returns to the interpreter, or that blocks SIGALRM, cannot be ended from
  inside the process. Campaign workers publish the wall-clock time and simulation time at which
  their current step began (`HEARTBEAT`, shared memory); the campaign kills a worker whose step
  has lasted `limit + KILL_GRACE` s, records the run `failed` with the step's time, and starts a
  new worker (`campaigns.backends`). A single `aotv-cosim run` has no such outer process.

Only the main thread can receive signals, so the in-process interruption is active there only (the
command line, campaign workers, a notebook's own cell); `limited` leaves a run in another thread
unguarded.
"""

import contextlib
import signal
import threading
import time

from aotv_cosim.engine.errors import SimulationError

CAMPAIGN_STEP_TIMEOUT = 60.0
"""Step limit of campaigns and benchmarks when neither the scenario nor --step-timeout gives one, s.
The slowest shipped law (predictive guidance) takes well under a second per step."""
KILL_GRACE = 5.0
"""Seconds past the limit after which a campaign kills a worker whose step the signal did not end."""

HEARTBEAT = None
"""In a campaign worker: a shared array of two doubles, (monotonic time the current step began, its
simulation time); 0 in the first while no step is under way. None elsewhere."""


class StepTimeout(SimulationError):
    """A communication step that did not end within the step limit."""


class StepLimitReached(Exception):
    """Raised by the SIGALRM handler in the code that is running when a step's limit passes."""


_fired = []


def _alarm(signum, frame):
    _fired.append(True)
    raise StepLimitReached()


def timeout_error(limit: float, t: float, component=None, file=None) -> StepTimeout:
    """The StepTimeout of a step from `t` (s) that took more than `limit` s (component: the FMU
    that was stepping, when known)."""
    who = f"fmi2DoStep of {component} did not return" if component else "the step did not end"
    error = StepTimeout(f"step timeout: {who} within {limit:g} s at t = {t:.6g} s", file=file,
                        entry=component,
                        fix="the results up to this time are saved; fix the FMU's code, or raise "
                            "step_timeout (scenario) / --step-timeout if the step is just slow")
    error.component, error.time, error.variable = component or "master", t, None
    return error


def limited(advance, limit):
    """`advance(t, step, t_new)` with every call limited to `limit` s of wall-clock time (None or 0:
    `advance` itself). In a campaign worker each step also sets `HEARTBEAT`."""
    beat = HEARTBEAT
    guard = limit and threading.current_thread() is threading.main_thread()
    if not guard and beat is None:
        return advance
    setitimer, real, clock = signal.setitimer, signal.ITIMER_REAL, time.monotonic

    def guarded(t, step, t_new):
        if beat is not None:
            beat[1], beat[0] = t, clock()
        if not guard:
            return advance(t, step, t_new)
        _fired.clear()
        setitimer(real, limit)
        try:
            advance(t, step, t_new)
        except (SimulationError, StepLimitReached) as exc:
            if not _fired:
                raise
            raise timeout_error(limit, t, *_stepping(exc)) from None
        finally:
            setitimer(real, 0)
    return guarded


def _stepping(exc):
    """(component, FMU file name) of the FMU whose step the alarm interrupted: the one the master's
    failure names, else the last FMU instance held by a frame of the traceback (an alarm landing in
    the master's own code between two FMU calls), else (None, None)."""
    if getattr(exc, "component", None):
        return exc.component, exc.file
    from aotv_cosim.engine.fmi_instance import FmuInstance

    found, tb = None, exc.__traceback__
    while tb is not None:
        found = next((v for v in tb.tb_frame.f_locals.values() if isinstance(v, FmuInstance)), found)
        tb = tb.tb_next
    return (found.name, found.info.path.name) if found is not None else (None, None)


@contextlib.contextmanager
def armed(limit):
    """Install the SIGALRM handler for a run limited to `limit` s per step (main thread only; else,
    or without a limit, nothing). The previous handler is put back after the run."""
    guard = limit and threading.current_thread() is threading.main_thread()
    previous = signal.signal(signal.SIGALRM, _alarm) if guard else None
    try:
        yield
    finally:
        if guard:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, previous if previous is not None else signal.SIG_DFL)
        if HEARTBEAT is not None:  # no step under way until the next run's first
            HEARTBEAT[0] = 0.0
