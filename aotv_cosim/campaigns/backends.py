"""Where the runs execute: local replaceable worker processes or a Dask distributed cluster.

A backend (`Local`, `Dask`, made by `opened`) takes batches [(run, values), ...] of a scenario
(`ScenarioRef`) with the command's options object, which travels whole to the worker (a local
process or a Dask task: `worker.run_one`, `worker.run_batch`), and gives back (batch, rows) as runs
finish. `stream` feeds a backend from a lazy iterable of runs, keeping only a few batches ahead of
the workers, so a campaign's draws are made as the runs go (memory bounded by the runs in flight,
and a SIGINT is seen while draws are made). The corridor submits its runs one by one.

Locally each run is one task of a `pool.WorkerPool`: a run whose worker crashes, hangs in native
code or outgrows the memory limit is returned as a row with status 'failed' and the cause in
`error`, its worker is replaced, and the other runs go on. On Dask a batch whose task fails is
split and its runs retried one by one; a single run that still fails is returned as a 'failed' row.
"""

import math
import multiprocessing
import os
import time
from typing import Any

from threadpoolctl import threadpool_limits

from aotv_cosim.campaigns.orphans import terminate, worker_started
from aotv_cosim.campaigns.pool import DEPTH, WorkerLost, WorkerPool
from aotv_cosim.campaigns.scenario_ref import ScenarioRef
from aotv_cosim.campaigns.worker import release, run_batch, run_one
from aotv_cosim.errors import InputError, SimulationError
from aotv_cosim.options.checks import usable_cores
from aotv_cosim.simulation import interrupts, watchdog
from aotv_cosim.simulation.interrupts import Interrupted
from aotv_cosim.status import Status

NO_WORKER_PATIENCE = 60.0
"""Seconds a Dask campaign waits with tasks pending and no worker in the cluster before it fails
(workers that died at start, e.g. unable to import aotv_cosim, would leave it waiting forever)."""

__all__ = ["Dask", "Local", "batches", "failed_row", "opened", "stream", "usable_cores"]


def failed_row(columns, run, values, error) -> dict:
    """The row of a run that gave none (its worker was lost, or its task raised): status 'failed',
    the cause in `error` (a WorkerLost's message as it is, else the exception's type and message)."""
    row: dict[str, Any] = dict.fromkeys(columns, math.nan)
    row.update({f"dispersed.{k}": v for k, v in values.items()})
    cause = str(error) if isinstance(error, WorkerLost) else f"{type(error).__name__}: {error}"
    row.update(run=run, status=Status.FAILED, error=cause)
    if "outcome" in row:
        row.update({"outcome": "failed", "outcome.reason": cause})
    return row


def batches(work, remaining: int, workers: int):
    """Batches (lists) of consecutive items of the iterable `work` (`remaining` of them), shrinking
    to the end (guided scheduling): each holds an eighth of a worker's share of the items still to
    batch, at most 25 and at least 1. A batch amortizes the Dask task overhead, and the last ones
    are single runs, so no worker idles long while another finishes a batch: with even batches of
    12, 200 predictive-law runs on 2 workers kept the workers busy 89 % of the wall time. Items are
    taken from `work` only as batches are asked for."""
    items = iter(work)
    while remaining > 0:
        size = max(1, min(25, remaining // (8 * max(1, workers))))
        batch = [item for _, item in zip(range(size), items)]
        if not batch:
            return
        remaining -= len(batch)
        yield batch


WORKER_BLAS_THREADS = 1
"""BLAS threads of a local worker, however many workers: the laws' matrices are a few rows, and
a 40-run LQR-law campaign on one worker cost 2.2-2.5 s of CPU with one thread against 3.4-4.5 s
with one per core (2 here; OpenBLAS threads spin while they wait)."""
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS")
"""Environment variables from which BLAS and OpenMP libraries take their thread count when they load."""


def _pool(workers, step_limit=watchdog.CAMPAIGN_STEP_TIMEOUT, max_rss=None):
    methods = multiprocessing.get_all_start_methods()
    context = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
    return WorkerPool(workers, context, initializer=_started, finalizer=release, step_limit=step_limit,
                      max_rss=max_rss, initargs=(os.getpid(), WORKER_BLAS_THREADS))


def _started(parent_pid, blas_threads):
    """Initializer of a local pool worker: it dies with its parent (`orphans.worker_started`) and
    uses at most `blas_threads` BLAS threads (`WORKER_BLAS_THREADS`). OpenBLAS threads spin while
    they wait, so workers that each run one thread per core fight for the cores: on 2 cores two
    workers ran 100 LQR-law runs in 6.3 s against 4.1 s for one (bench/bench_campaign_laws.py),
    and in 2.9 s with one BLAS thread each. The libraries already loaded are limited now
    (threadpoolctl); those loaded later, as scipy's own OpenBLAS when the first FMU imports
    scipy, read the limit from the environment set here. Dask's nanny sets the same limit for
    its workers."""
    worker_started(parent_pid)
    os.environ.update(dict.fromkeys(BLAS_THREAD_VARIABLES, str(blas_threads)))
    threadpool_limits(limits=blas_threads, user_api="blas")


class Local:
    """Runs on `options.workers` replaceable local processes (`pool`), one task per run; a step
    limit of `step_limit` s and `options.max_rss` MiB per worker.

    On a SIGINT/SIGTERM (see `interrupts`) `finished` raises Interrupted within `pool.POLL` s;
    `close` then kills the workers: the runs in flight are not recorded, and a resumed campaign
    runs them again."""

    def __init__(self, options, step_limit, columns):
        self.options, self.columns = options, columns
        self.pool = _pool(options.workers, step_limit, options.max_rss_bytes)
        self.tasks = {}
        self.ahead = options.workers * (DEPTH + 1)
        """Batches worth submitting ahead of the workers (each worker holds DEPTH runs)."""
        self.workers = options.workers

    @property
    def pending(self) -> int:
        return len(self.tasks)

    def submit(self, ref: ScenarioRef, batch) -> None:
        for run, values in batch:
            self.tasks[self.pool.submit(run_one, ref, self.options, run, values)] = (run, values)

    def finished(self) -> list:
        """[(batch, rows)] of the runs finished since the last call (at least one while any is pending)."""
        done = []
        for task in self.pool.wait_any():
            item = self.tasks.pop(task, None)
            if item is None:
                continue
            try:
                rows = [task.result()]
            except Exception as exc:  # WorkerLost, or an error outside a run
                run, values = item
                rows = [failed_row(self.columns, run, values, exc)]
            done.append(([item], rows))
        return done

    def close(self, interrupted=False) -> None:
        if interrupted:
            terminate(self.pool)
        self.pool.shutdown(wait=True, cancel_futures=True)


class Dask:
    """Runs on the Dask scheduler at `options.scheduler` (a Client object is accepted too), one task
    per batch; fails after `patience` s without a worker. Dask runs tasks in worker threads, where
    the step watchdog cannot interrupt a step (`simulation.watchdog`); a crashed worker is
    restarted by its nanny and its runs retried here."""

    def __init__(self, options, columns, patience=NO_WORKER_PATIENCE):
        from distributed import Client

        address = options.scheduler
        self.own = not isinstance(address, Client)
        self.client = _client(address) if self.own else address
        self.options, self.columns, self.patience = options, columns, patience
        self.futures = {}
        self.alone_since = None
        threads = sum(self.client.nthreads().values()) if self.client.scheduler_info().get("workers") else 0
        self.workers = max(options.workers, threads, 1)
        self.ahead = 2 * self.workers

    @property
    def pending(self) -> int:
        return len(self.futures)

    def submit(self, ref: ScenarioRef, batch) -> None:
        future = self.client.submit(run_batch, ref, self.options, batch, pure=False)
        self.futures[future] = (ref, tuple(batch))

    def finished(self) -> list:
        """[(batch, rows)] of the batches finished; a failed batch is split and retried run by run;
        SimulationError once the cluster has had no worker for `patience` s while some are pending."""
        from distributed import wait

        while True:
            if interrupts.received():
                raise Interrupted(interrupts.name())
            try:
                done, _ = wait(list(self.futures), timeout=min(0.5, self.patience), return_when="FIRST_COMPLETED")
            except TimeoutError:
                done = set()
            self._watch_workers(done)
            results = []
            for future in done:
                ref, batch = self.futures.pop(future)
                try:
                    results.append((list(batch), future.result()))
                except Exception as exc:  # KilledWorker after Dask's own retries, or a task error
                    if len(batch) > 1:
                        for item in batch:
                            self.submit(ref, [item])
                    else:
                        run, values = batch[0]
                        results.append((list(batch), [failed_row(self.columns, run, values, exc)]))
                finally:
                    future.release()
            if results or not self.futures:
                return results

    def _watch_workers(self, done):
        if done or self.client.scheduler_info().get("workers"):
            self.alone_since = None
        elif self.alone_since is None:
            self.alone_since = time.monotonic()
        elif time.monotonic() - self.alone_since >= self.patience:
            raise SimulationError(f"the Dask cluster has had no worker for {self.patience:g} s with "
                                  f"{len(self.futures)} batch(es) pending", file=self.client.scheduler.address,
                                  entry="--scheduler", fix="start workers that can import aotv_cosim "
                                  "(see their logs), or run on local workers")

    def close(self, interrupted=False) -> None:
        for future in self.futures:
            future.cancel()
        self.futures.clear()
        if self.own:
            self.client.close()


def _client(address: str):
    """A distributed.Client of the scheduler at `address`; InputError when Dask cannot make one of
    it (an address of a transport it has not, such as inproc:// of another process, or no scheduler
    answering there)."""
    from distributed import Client

    try:
        return Client(address)
    except (OSError, ValueError, TypeError, RuntimeError, MemoryError) as exc:  # what distributed raises for an address
        raise InputError(f"cannot connect to the Dask scheduler: {type(exc).__name__}: {exc}", file=address,
                         entry="--scheduler", fix="give tcp://HOST:PORT of a running scheduler "
                                                  "(e.g. tcp://127.0.0.1:8786)") from None


def opened(options, step_limit, columns):
    """The backend of the command's `options`: `Dask` with a scheduler, else `Local`."""
    return Local(options, step_limit, columns) if options.scheduler is None else Dask(options, columns)


def stream(backend, ref: ScenarioRef, work, remaining: int):
    """Yield row lists of the (run, values) items of the lazy iterable `work` (`remaining` items),
    submitted to `backend` in `batches` a few ahead of its workers (`backend.ahead`). Raises
    Interrupted (checked between draws too) on a SIGINT/SIGTERM."""
    queued = batches(work, remaining, backend.workers)

    def top_up():
        while backend.pending < backend.ahead:
            if interrupts.received():
                raise Interrupted(interrupts.name())
            batch = next(queued, None)
            if batch is None:
                return
            backend.submit(ref, batch)

    top_up()
    while backend.pending:
        for _, rows in backend.finished():
            yield rows
        top_up()
