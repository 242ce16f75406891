"""Tiles of an offline render traced by worker processes (both cores), in job order.

Embree holds the GIL in ``embreex``, so threads do not help; processes do. Workers are
spawned (no fork of a process that may hold GL or Embree threads) and each builds its own
scene context once, in ``init``. A few tiles are in flight at a time; closing the consuming
generator cancels the tiles not started.
"""

from __future__ import annotations

import multiprocessing
from concurrent.futures import ProcessPoolExecutor
from typing import Callable, Iterator


def traced_in_pool(init: Callable, init_args: tuple, task: Callable, jobs: list,
                   task_args: Callable[[tuple], tuple], workers: int) -> Iterator[tuple]:
    """Yield (job, task(*task_args(job))) for each job, in order, from ``workers`` processes."""
    pool = ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"),
                               initializer=init, initargs=init_args)
    pending: list = []
    try:
        queue = iter(jobs)
        for job in queue:
            pending.append((job, pool.submit(task, *task_args(job))))
            if len(pending) >= 2 * workers:
                break
        while pending:
            job, future = pending.pop(0)
            result = future.result()
            next_job = next(queue, None)
            if next_job is not None:
                pending.append((next_job, pool.submit(task, *task_args(next_job))))
            yield job, result
    finally:
        pool.shutdown(wait=False, cancel_futures=True)
