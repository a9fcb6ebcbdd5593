"""Where the runs execute: a local process pool or a Dask distributed cluster.

Both take batches [(run, values), ...] and yield lists of rows as batches finish. A batch whose
task fails (its worker process crashed, or the task raised) is split and its runs retried one by
one on a fresh pool; a single run that still fails is returned as a row with status 'crashed'.
"""

import concurrent.futures as cf
import math
import multiprocessing
import os
import time

from threadpoolctl import threadpool_limits

from aotv_cosim.engine import interrupts
from aotv_cosim.engine.errors import SimulationError
from aotv_cosim.engine.master import Interrupted
from aotv_cosim.campaigns.orphans import terminate, worker_started
from aotv_cosim.campaigns.worker import run_batch

POLL = 0.2
"""Seconds between two looks at the interruption flag while waiting for local batches."""
NO_WORKER_PATIENCE = 60.0
"""Seconds a Dask campaign waits with tasks pending and no worker in the cluster before it fails
(workers that died at start, e.g. unable to import aotv_cosim, would leave it waiting forever)."""


def crashed_row(columns, run, values, error) -> dict:
    row = dict.fromkeys(columns, math.nan)
    row.update({f"dispersed.{k}": v for k, v in values.items()})
    row.update(run=run, status="crashed", error=f"{type(error).__name__}: {error}")
    return row


def _retry_plan(batch):
    """Split a failed batch into single runs; None when it already is one."""
    return [[item] for item in batch] if len(batch) > 1 else None


def usable_cores() -> int:
    """The cores this process may run on (its CPU affinity where the OS has one)."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def _pool(workers):
    methods = multiprocessing.get_all_start_methods()
    context = multiprocessing.get_context("fork" if "fork" in methods else "spawn")
    return cf.ProcessPoolExecutor(max_workers=workers, mp_context=context, initializer=_started,
                                  initargs=(os.getpid(), max(1, usable_cores() // workers)))


BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS")
"""Environment variables from which BLAS and OpenMP libraries take their thread count when they load."""


def _started(parent_pid, blas_threads):
    """Initializer of a local pool worker: it dies with its parent (`orphans.worker_started`) and
    uses at most `blas_threads` BLAS threads, its share of the cores. OpenBLAS threads spin while
    they wait, so workers that each run one thread per core fight for the cores: on 2 cores two
    workers ran 100 LQR-law runs in 6.3 s against 4.1 s for one (bench/bench_campaign_laws.py),
    and in 2.9 s with one BLAS thread each. The libraries already loaded are limited now
    (threadpoolctl); those loaded later, as scipy's own OpenBLAS when the first FMU imports
    scipy, read the limit from the environment set here. Dask's nanny sets the same limit for
    its workers."""
    worker_started(parent_pid)
    os.environ.update(dict.fromkeys(BLAS_THREAD_VARIABLES, str(blas_threads)))
    threadpool_limits(limits=blas_threads, user_api="blas")


def _finished(futures):
    """Yield futures as they finish; raise Interrupted within POLL s of a SIGINT/SIGTERM."""
    pending = set(futures)
    while pending:
        done, pending = cf.wait(pending, timeout=POLL, return_when=cf.FIRST_COMPLETED)
        if interrupts.received():
            raise Interrupted(interrupts.name())
        yield from done


def local(scenario_path, sets, batches, workers, columns, times=None):
    """Yield row lists from a pool of `workers` processes (times: (start, stop) overrides or None).

    A crash breaks the whole pool and fails every batch in flight, so a failed batch is retried
    on a new pool as single runs, and a single run that fails again is run alone in a pool of
    its own: only a run that then fails is the one that crashes. On a SIGINT/SIGTERM (see
    `interrupts`) it raises Interrupted and kills the workers: the runs in flight are not
    recorded, and a resumed campaign runs them again.
    """
    queue = [(b, False) for b in batches]
    while queue:
        shared = [b for b, alone in queue if not alone]
        isolated = [[b] for b, alone in queue if alone]
        queue = []
        for group, size in [(shared, workers)] + [(g, 1) for g in isolated]:
            if not group:
                continue
            pool = _pool(size)
            try:
                futures = {pool.submit(run_batch, scenario_path, sets, b, times): b for b in group}
                for future in _finished(futures):
                    batch = futures[future]
                    try:
                        yield future.result()
                    except Exception as exc:  # BrokenProcessPool or an error outside a run
                        if size == 1:
                            yield [crashed_row(columns, *batch[0], exc)]
                        else:
                            split = _retry_plan(batch)
                            queue += [(b, False) for b in split] if split else [(batch, True)]
            except BaseException:  # interrupted, or the consumer stopped: running batches are dropped
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


def dask(scenario_path, sets, batches, address, columns, times=None, patience=NO_WORKER_PATIENCE):
    """Yield row lists from the Dask scheduler at `address` (a Client object is accepted too);
    fail after `patience` s without a worker (`_completed`)."""
    from distributed import Client

    client = address if isinstance(address, Client) else Client(address)
    try:
        queue = list(batches)
        while queue:
            futures = {client.submit(run_batch, scenario_path, sets, b, times, pure=False): tuple(b)
                       for b in queue}
            queue = []
            for future in _completed(client, futures, patience):
                batch = list(futures[future])
                try:
                    yield future.result()
                except Exception as exc:  # KilledWorker after Dask's own retries, or a task error
                    split = _retry_plan(batch)
                    if split is None:
                        yield [crashed_row(columns, *batch[0], exc)]
                    else:
                        queue += split
                finally:
                    future.release()
    finally:
        if client is not address:
            client.close()
