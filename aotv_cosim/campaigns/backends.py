"""Where the runs execute: local replaceable worker processes or a Dask distributed cluster.

Both take batches [(run, values), ...] and yield lists of rows as runs finish. Locally each run is
one task of a `pool.WorkerPool`: a run whose worker crashes, hangs in native code or outgrows the
memory limit is returned as a row with status 'failed' and the cause in `error`, its worker is
replaced, and the other runs go on. On Dask a batch whose task fails is split and its runs retried
one by one; a single run that still fails is returned as a 'failed' row.
"""

import math
import multiprocessing
import os
import time

from threadpoolctl import threadpool_limits

from aotv_cosim.simulation import watchdog
from aotv_cosim.errors import SimulationError
from aotv_cosim.campaigns.orphans import terminate, worker_started
from aotv_cosim.campaigns.pool import DEFAULT_MAX_RSS, WorkerLost, WorkerPool
from aotv_cosim.campaigns.scenario_ref import ScenarioRef
from aotv_cosim.campaigns.worker import release, run_batch, run_one
from aotv_cosim.status import Status

NO_WORKER_PATIENCE = 60.0
"""Seconds a Dask campaign waits with tasks pending and no worker in the cluster before it fails
(workers that died at start, e.g. unable to import aotv_cosim, would leave it waiting forever)."""


def failed_row(columns, run, values, error) -> dict:
    """The row of a run that gave none (its worker was lost, or its task raised): status 'failed',
    the cause in `error` (a WorkerLost's message as it is, else the exception's type and message)."""
    row = dict.fromkeys(columns, math.nan)
    row.update({f"dispersed.{k}": v for k, v in values.items()})
    cause = str(error) if isinstance(error, WorkerLost) else f"{type(error).__name__}: {error}"
    row.update(run=run, status=Status.FAILED, error=cause)
    if "outcome" in row:
        row.update({"outcome": "failed", "outcome.reason": cause})
    return row


def _retry_plan(batch):
    """Split a failed batch into single runs; None when it already is one."""
    return [[item] for item in batch] if len(batch) > 1 else None


def usable_cores() -> int:
    """The cores this process may run on (its CPU affinity where the OS has one)."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


WORKER_BLAS_THREADS = 1
"""BLAS threads of a local worker, however many workers: the laws' matrices are a few rows, and
a 40-run LQR-law campaign on one worker cost 2.2-2.5 s of CPU with one thread against 3.4-4.5 s
with one per core (2 here; OpenBLAS threads spin while they wait)."""


def _pool(workers, step_limit=watchdog.CAMPAIGN_STEP_TIMEOUT, max_rss=DEFAULT_MAX_RSS):
    methods = multiprocessing.get_all_start_methods()
    context = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
    return WorkerPool(workers, context, initializer=_started, finalizer=release, step_limit=step_limit,
                      max_rss=max_rss, initargs=(os.getpid(), WORKER_BLAS_THREADS))


BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS")
"""Environment variables from which BLAS and OpenMP libraries take their thread count when they load."""


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


def local(ref: ScenarioRef, batches, workers, columns, step_limit=watchdog.CAMPAIGN_STEP_TIMEOUT,
          max_rss=DEFAULT_MAX_RSS, keep_series=False, fmi_calls=None):
    """Yield row lists of the scenario `ref` from `workers` replaceable processes (step_limit: s
    per step; max_rss: bytes per worker, None for no limit; see `pool`; keep_series: each row
    carries its run's decimated signals; fmi_calls: as for `worker.Runner`).

    On a SIGINT/SIGTERM (see `interrupts`) it raises Interrupted within `pool.POLL` s and kills
    the workers: the runs in flight are not recorded, and a resumed campaign runs them again.
    """
    pool = _pool(workers, step_limit, max_rss)
    try:
        tasks = {pool.submit(run_one, ref, run, values, step_limit, keep_series, fmi_calls): (run, values)
                 for batch in batches for run, values in batch}
        for task in pool.completed(tasks):
            try:
                yield [task.result()]
            except Exception as exc:  # WorkerLost, or an error outside a run
                yield [failed_row(columns, *tasks[task], exc)]
    except BaseException:  # interrupted, or the consumer stopped: running tasks are dropped
        terminate(pool)
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _completed(client, futures, patience):
    """The futures as they finish; SimulationError once the cluster has had no worker for
    `patience` s while some are pending."""
    from distributed import wait

    pending, alone_since = set(futures), None
    while pending:
        try:
            done, pending = wait(pending, timeout=min(5.0, patience), return_when="FIRST_COMPLETED")
        except TimeoutError:
            done = set()
        yield from done
        if done or client.scheduler_info().get("workers"):
            alone_since = None
        elif alone_since is None:
            alone_since = time.monotonic()
        elif time.monotonic() - alone_since >= patience:
            raise SimulationError(f"the Dask cluster has had no worker for {patience:g} s with "
                                  f"{len(pending)} batch(es) pending", file=client.scheduler.address,
                                  entry="--scheduler", fix="start workers that can import aotv_cosim "
                                  "(see their logs), or run on local workers")


def dask(ref: ScenarioRef, batches, address, columns, patience=NO_WORKER_PATIENCE, keep_series=False,
         fmi_calls=None):
    """Yield row lists of the scenario `ref` from the Dask scheduler at `address` (a Client object is accepted too);
    fail after `patience` s without a worker (`_completed`). Dask runs tasks in worker threads,
    where the step watchdog cannot interrupt a step (`simulation.watchdog`); a crashed worker is
    restarted by its nanny and its runs retried here."""
    from distributed import Client

    client = address if isinstance(address, Client) else Client(address)
    try:
        queue = list(batches)
        while queue:
            futures = {client.submit(run_batch, ref, b, keep_series, fmi_calls, pure=False): tuple(b)
                       for b in queue}
            queue = []
            for future in _completed(client, futures, patience):
                batch = list(futures[future])
                try:
                    yield future.result()
                except Exception as exc:  # KilledWorker after Dask's own retries, or a task error
                    split = _retry_plan(batch)
                    if split is None:
                        yield [failed_row(columns, *batch[0], exc)]
                    else:
                        queue += split
                finally:
                    future.release()
    finally:
        if client is not address:
            client.close()
