"""The step watchdog: a communication step that does not end within its wall-clock limit fails the run.

FMUs run in the master's own interpreter (FMPy calls the FMU's C entry points; a pythonfmu FMU's
`do_step` is Python run by this interpreter). A step that hangs is ended in one of two ways:

- Python code that hangs (a loop, a sleep, a wait on a lock or a socket) is interrupted in the
  process. Each step counts itself in `PROGRESS` (three list stores, no system call: a
  `setitimer` per step cost 13 us a step on the development machine, 10 % of a 4-FMU step); a
  monitor thread started by `armed` looks every `limit / 4` s (at most 1 s) and, when the same
  step has run longer than the limit, sends SIGALRM to the main thread. Its handler raises
  `StepLimitReached` in whatever the main thread runs, which for a hung FMU is the FMU's own code
  (a blocking sleep or wait returns with EINTR first): pythonfmu reports the exception as fmi2Fatal, the master raises
  its `SimulationError` naming that component, and `limited` turns it into `StepTimeout` ("step
  timeout: fmi2DoStep of COMP did not return within N s at t = T s"): the run is `failed`, its
  rows up to t kept. The limit is met within limit + limit / 4.
- Native code that never returns to the interpreter, or that blocks SIGALRM, cannot be ended from
  inside the process. In a campaign worker the monitor also copies `PROGRESS` into `SHARED`,
  memory its campaign reads: the campaign kills a worker whose published step count has not
  moved for `limit + KILL_GRACE` s during a step (a native call that holds the GIL also stops the
  monitor, which is as good), records the run `failed` with the step's time, and starts a new
  worker (`campaigns.pool`). A single `aotv-cosim run` has no such outer process.

Only the main thread receives signals, so the watchdog guards runs made in the main thread (the
command line, campaign workers, a notebook's own cell); a run in another thread is not limited.
"""

import contextlib
import math
import signal
import threading
import time

from aotv_cosim.errors import SimulationError

CAMPAIGN_STEP_TIMEOUT = 60.0
"""Step limit of campaigns and benchmarks when neither the scenario nor --step-timeout gives one, s.
The slowest shipped law (predictive guidance) takes well under a second per step."""
MIN_STEP_TIMEOUT = 0.1
"""Smallest step limit, s (the scenario schema's minimum too). The monitor looks every limit / 4 s,
and it gets the interpreter when the main thread hands it over, every 5 ms
(`sys.getswitchinterval`): a smaller limit could not be met within 25 %, and below about 10 ms it
is never seen at all (a run with `--step-timeout 1e-9` was flown unlimited)."""
KILL_GRACE = 5.0
"""Seconds past the limit after which a campaign kills a worker whose step the signal did not end."""

PROGRESS = [0, 0.0, False]
"""(steps begun, simulation time of the last one in s, whether a step is under way)."""
SHARED = None
"""In a campaign worker: an array of two doubles in shared memory, (steps begun, time of the step
under way, NaN when none), copied from PROGRESS by the monitor. None elsewhere."""


class StepTimeout(SimulationError):
    """A communication step that did not end within the step limit."""


class StepLimitReached(Exception):
    """Raised by the SIGALRM handler in the code that is running when a step's limit passes."""


_fired: list = []


def _alarm(signum, frame):
    if PROGRESS[2]:  # an alarm arriving after its step ended does nothing
        _fired.append(True)
        raise StepLimitReached()


def timeout_error(limit: float, t: float, component=None, file=None, call="fmi2DoStep") -> StepTimeout:
    """The StepTimeout of a step from `t` (s) that took more than `limit` s (component: the FMU
    that was stepping, when known; call: its step function)."""
    who = f"{call} of {component} did not return" if component else "the step did not end"
    return StepTimeout(f"step timeout: {who} within {limit:g} s at t = {t:.6g} s", file=file,
                       entry=component,
                       fix="the results up to this time are saved; fix the FMU's code, or raise "
                           "step_timeout (scenario) / --step-timeout if the step is just slow",
                       component=component or "master", time=t)


def limited(advance, limit, step_calls=None):
    """`advance(t, step, t_new)` with every call limited to `limit` s of wall-clock time by the
    monitor of `armed` (None or 0, or outside the main thread: `advance` itself); step_calls:
    {component: the name of its step function} for the message (default fmi2DoStep)."""
    if not limit or threading.current_thread() is not threading.main_thread():
        return advance
    progress = PROGRESS

    def guarded(t, step, t_new):
        progress[0] += 1
        progress[1] = t
        try:
            progress[2] = True
            advance(t, step, t_new)
        except (SimulationError, StepLimitReached) as exc:
            if not _fired:
                raise
            component, file = _stepping(exc)
            raise timeout_error(limit, t, component, file, (step_calls or {}).get(component, "fmi2DoStep")) from None
        finally:
            progress[2] = False
    return guarded


def _stepping(exc):
    """(component, FMU file name) of the FMU whose step the alarm interrupted: the one the master's
    failure names, else the last FMU instance held by a frame of the traceback (an alarm landing in
    the master's own code between two FMU calls), else (None, None)."""
    if isinstance(exc, SimulationError) and exc.component:
        return exc.component, exc.file
    from aotv_cosim.simulation.instance import FmuInstance

    found, tb = None, exc.__traceback__
    while tb is not None:
        found = next((v for v in tb.tb_frame.f_locals.values() if isinstance(v, FmuInstance)), found)
        tb = tb.tb_next
    return (found.name, found.info.path.name) if found is not None else (None, None)


def _monitor(limit, stop, main):
    """Send SIGALRM to the main thread (`main`, its ident) once a step has run `limit` s; publish
    the progress to SHARED (when set) at each look."""
    poll, seen, since = min(1.0, limit / 4), None, time.monotonic()
    while not stop.wait(poll):
        count, t, stepping = PROGRESS
        if SHARED is not None:
            SHARED[0], SHARED[1] = count, t if stepping else math.nan
        if count != seen or not stepping:
            seen, since = count, time.monotonic()
        elif time.monotonic() - since > limit:
            signal.pthread_kill(main, signal.SIGALRM)
            since = math.inf  # once per step: a step that ignores it is the campaign's to end


@contextlib.contextmanager
def armed(limit):
    """Limit the steps of the run made inside to `limit` s each (main thread only; else, or without
    a limit, nothing): the SIGALRM handler and the monitor thread, removed after the run."""
    if not limit or threading.current_thread() is not threading.main_thread():
        yield
        return
    _fired.clear()
    previous = signal.signal(signal.SIGALRM, _alarm)
    stop = threading.Event()
    watcher = threading.Thread(target=_monitor, args=(limit, stop, threading.get_ident()),
                               name="aotv-step-watchdog", daemon=True)
    watcher.start()
    try:
        yield
    finally:
        stop.set()
        watcher.join()
        if SHARED is not None:
            SHARED[1] = math.nan  # no step under way until the next run's first
        signal.signal(signal.SIGALRM, previous if previous is not None else signal.SIG_DFL)
