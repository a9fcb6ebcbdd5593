"""Where the runs execute: a local process pool or a Dask distributed cluster.

Both take batches [(run, values), ...] and yield lists of rows as batches finish. A batch whose
task fails (its worker process crashed, or the task raised) is split and its runs retried one by
one on a fresh pool; a single run that still fails is returned as a row with status 'crashed'.
"""

import concurrent.futures as cf
import math
import multiprocessing

from aotv_cosim.montecarlo.worker import run_batch


def crashed_row(columns, run, values, error) -> dict:
    row = dict.fromkeys(columns, math.nan)
    row.update({f"dispersed.{k}": v for k, v in values.items()})
    row.update(run=run, status="crashed", error=f"{type(error).__name__}: {error}")
    return row


def _retry_plan(batch):
    """Split a failed batch into single runs; None when it already is one."""
    return [[item] for item in batch] if len(batch) > 1 else None


def local(scenario_path, sets, batches, workers, columns):
    """Yield row lists from a pool of `workers` processes (restarted after a crash)."""
    queue = list(batches)
    context = multiprocessing.get_context("fork" if "fork" in multiprocessing.get_all_start_methods()
                                          else "spawn")
    while queue:
        with cf.ProcessPoolExecutor(max_workers=workers, mp_context=context) as pool:
            futures = {pool.submit(run_batch, scenario_path, sets, b): b for b in queue}
            queue = []
            for future in cf.as_completed(futures):
                batch = futures[future]
                try:
                    yield future.result()
                except Exception as exc:  # BrokenProcessPool or an error outside a run
                    split = _retry_plan(batch)
                    if split is None:
                        yield [crashed_row(columns, *batch[0], exc)]
                    else:
                        queue += split


def dask(scenario_path, sets, batches, address, columns):
    """Yield row lists from the Dask scheduler at `address` (a Client object is accepted too)."""
    from distributed import Client, as_completed

    client = address if isinstance(address, Client) else Client(address)
    try:
        queue = list(batches)
        while queue:
            futures = {client.submit(run_batch, scenario_path, sets, b, pure=False): tuple(b)
                       for b in queue}
            queue = []
            for future in as_completed(futures):
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
