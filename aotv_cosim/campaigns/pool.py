"""Local campaign workers that can be replaced: a run that hangs, crashes its process or grows past a
memory limit costs that run and its worker, not the campaign.

Each worker is a process with a pipe of its own; it runs its tasks one at a time (a campaign sends
one run per task) and answers each with its result. Every worker is given `DEPTH` tasks ahead, so
it starts the next run without waiting for the parent to read the last row (on a loaded machine
that wait left workers idle: 30 % more wall time on 100 runs). The parent drives the pool from its
own thread (no helper thread, so every worker is forked from the main thread) and, every `POLL` s
and whenever a pipe or process stirs, looks at each busy worker; its first unanswered task is the
run under way:

- its process ended (SIGSEGV, abort, os._exit): the task fails with `WorkerLost` "crash: ...",
  the signal or exit status named;
- its step count (published by the worker in shared memory, `watchdog.SHARED`) has not moved
  for `step_limit + KILL_GRACE` s while a step is under way (a step that hangs in Python is ended
  sooner inside the worker by the step watchdog, so this catches what a signal cannot end: native
  code): the worker is killed, the task fails with "step timeout: ..." naming the step's time;
- its resident set size (/proc/PID/statm, Linux) is above `max_rss` bytes: the worker is killed,
  the task fails with "memory: ...".

A lost worker is replaced at once, the tasks it had not started go back to the queue, and the
other workers and their tasks are untouched. On
`terminate` (an interruption) every worker is killed; `shutdown` asks them to exit, which they do
after closing what they hold (`finalizer`, e.g. FMU instances, so no library is left to exit-time
destructors), and returns their exit codes.
"""

import collections
import contextlib
import math
import os
import signal
import time
from multiprocessing import connection

from aotv_cosim.simulation import interrupts, watchdog
from aotv_cosim.simulation.interrupts import Interrupted

POLL = 0.2
"""Seconds between two looks at the workers' steps and memory, and at the interruption flag."""
DEPTH = 2
"""Tasks a worker holds: the one under way and the next."""
_PAGE = os.sysconf("SC_PAGE_SIZE") if hasattr(os, "sysconf") else 4096


class WorkerLost(Exception):
    """A task whose worker crashed, hung or outgrew the memory limit (the message says which)."""


class Task:
    """A submitted call: `result()` drives the pool until it is done, then returns or raises."""

    def __init__(self, pool, fn, args):
        self.pool, self.call = pool, (fn, args)
        self.done, self.value, self.error = False, None, None

    def finish(self, value=None, error=None):
        self.done, self.value, self.error = True, value, error
        self.pool.finished.append(self)

    def result(self):
        while not self.done:
            self.pool.poll(POLL)
        if self.error is not None:
            raise self.error
        return self.value


def _serve(conn, progress, initializer, initargs, finalizer):
    """A worker's life: run (fn, args) calls received on `conn` until None or the pipe closes."""
    if initializer is not None:
        initializer(*initargs)
    watchdog.SHARED = progress
    try:
        while True:
            try:
                call = conn.recv()
            except EOFError:
                break
            if call is None:
                break
            fn, args = call
            try:
                answer: tuple = (fn(*args), None)
            except Exception as exc:
                answer = (None, exc)
            try:
                conn.send(answer)
            except Exception as exc:  # an unpicklable result or error
                conn.send((None, RuntimeError(f"{type(exc).__name__}: {exc}")))
    finally:
        if finalizer is not None:
            finalizer()


class _Worker:
    def __init__(self, context, initializer, initargs, finalizer):
        self.progress = context.RawArray("d", 2)  # steps begun, time of the last (NaN: none under way)
        self.progress[1] = math.nan
        self.conn, child = context.Pipe()
        self.process = context.Process(target=_serve, daemon=True,
                                       args=(child, self.progress, initializer, initargs, finalizer))
        self.process.start()
        child.close()
        self.tasks: collections.deque = collections.deque()
        """Tasks sent and not answered, oldest (the one under way) first."""
        self.seen = (None, time.monotonic())
        """(step count last seen, monotonic time it was first seen)."""

    def stalled(self) -> float:
        """Seconds the worker's current step has run without the step count moving (0 outside a
        run's steps)."""
        count, now = self.progress[0], time.monotonic()
        if math.isnan(self.progress[1]) or count != self.seen[0]:
            self.seen = (count, now)
        return now - self.seen[1]

    def rss(self) -> int:
        """Resident set size in bytes (0 where /proc is not available)."""
        try:
            with open(f"/proc/{self.process.pid}/statm") as f:
                return int(f.read().split()[1]) * _PAGE
        except (OSError, ValueError, IndexError):
            return 0

    def kill(self):
        if self.process.is_alive():
            self.process.kill()
        self.process.join()
        self.conn.close()


def _death(exitcode) -> str:
    if exitcode is not None and exitcode < 0:
        try:
            return f"died of {signal.Signals(-exitcode).name}"
        except ValueError:
            return f"died of signal {-exitcode}"
    return f"exited with status {exitcode}"


class WorkerPool:
    """`max_workers` replaceable worker processes (see the module docstring).

    initializer(*initargs) runs first in each worker, finalizer() last; step_limit (s) and
    max_rss (bytes, None: no limit) are the limits a busy worker is held to."""

    def __init__(self, max_workers, mp_context, initializer=None, initargs=(), finalizer=None,
                 step_limit=watchdog.CAMPAIGN_STEP_TIMEOUT, max_rss=None):
        self.size, self.context = max_workers, mp_context
        self.start_args = (initializer, initargs, finalizer)
        self.step_limit, self.max_rss = step_limit, max_rss
        self.queue: collections.deque = collections.deque()
        self.finished: collections.deque = collections.deque()
        """Tasks done since `completed` last looked."""
        self.workers = []
        self.exitcodes = []
        """Exit codes of the workers that ended by `shutdown` (0 each when they exit cleanly)."""

    def submit(self, fn, *args) -> Task:
        task = Task(self, fn, args)
        self.queue.append(task)
        return task

    def wait_any(self) -> list:
        """The tasks finished since the last call, waiting for at least one while any is queued or
        under way; raise Interrupted within POLL s of a SIGINT/SIGTERM."""
        while True:
            if interrupts.received():
                raise Interrupted(interrupts.name())
            if self.finished or not (self.queue or any(w.tasks for w in self.workers)):
                done = list(self.finished)
                self.finished.clear()
                return done
            self.poll(POLL)

    def poll(self, timeout):
        """Give queued tasks to idle workers, wait up to `timeout` s for an answer, collect the
        answers, and replace the workers that crashed, hung or outgrew the memory limit."""
        self._dispatch()
        busy = [w for w in self.workers if w.tasks]
        if busy:
            connection.wait([w.conn for w in busy] + [w.process.sentinel for w in busy], timeout)
        for worker in busy:
            self._collect(worker)
        self._dispatch()

    def _dispatch(self):
        """Send queued tasks to the workers holding fewer than DEPTH, the least loaded first,
        starting workers up to `size` while none is idle (a worker found dead meanwhile is given up:
        its tasks go back to the queue, and `_collect` says why if it was running one)."""
        while self.queue:
            idle = [w for w in self.workers if not w.tasks]
            if not idle and len(self.workers) < self.size:  # a new worker only when none is idle
                self.workers.append(_Worker(self.context, *self.start_args))
            worker = min(self.workers, key=lambda w: len(w.tasks))
            if len(worker.tasks) >= DEPTH:
                return
            task = self.queue.popleft()
            try:
                worker.conn.send(task.call)
            except OSError:
                self.queue.appendleft(task)
                self._collect(worker)
                return
            worker.tasks.append(task)

    def _collect(self, worker):
        """Finish the tasks `worker` answered; give the worker up if `_lost` says so (its task
        under way fails with the cause, the others go back to the queue)."""
        try:
            while worker.tasks and worker.conn.poll():
                value, error = worker.conn.recv()
                worker.tasks.popleft().finish(value, error)
        except (EOFError, OSError):
            pass  # the process died; its exit code says how
        cause = self._lost(worker) if worker.tasks else None
        if cause is None and (worker.tasks or worker.process.is_alive()):
            return
        worker.kill()
        self.workers.remove(worker)
        if worker.tasks:
            current = worker.tasks.popleft()
            self.queue.extendleft(reversed(worker.tasks))
            current.finish(error=WorkerLost(cause))

    def _lost(self, worker):
        """Why a busy worker is to be given up, or None while it is well."""
        if not worker.process.is_alive():
            worker.process.join()
            return f"crash: the worker process {_death(worker.process.exitcode)} during this run (worker replaced)"
        if self.step_limit and worker.stalled() > self.step_limit + watchdog.KILL_GRACE:
            return (f"step timeout: the step at t = {worker.progress[1]:.6g} s did not end within "
                    f"{self.step_limit:g} s and a signal could not stop it (native code); the worker was "
                    "killed and replaced")
        if self.max_rss and worker.rss() > self.max_rss:
            return (f"memory: the worker's resident memory passed the limit of {self.max_rss / 2**20:g} MiB "
                    "during this run; the worker was killed and replaced")
        return None

    def terminate(self):
        """Kill every worker (their tasks are dropped)."""
        for worker in self.workers:
            worker.kill()
        self.workers = []

    def shutdown(self, wait=True, cancel_futures=True):
        """Ask every worker to exit (idle ones at once; with `wait`, busy ones after their task)
        and record their exit codes; queued tasks are dropped."""
        self.queue.clear()
        while wait and any(w.tasks for w in self.workers):
            self.poll(POLL)
        for worker in self.workers:
            with contextlib.suppress(OSError):
                worker.conn.send(None)
        for worker in self.workers:
            worker.process.join()
            self.exitcodes.append(worker.process.exitcode)
            worker.conn.close()
        self.workers = []
