"""Tiles of an offline render traced by worker processes (both cores), in job order.

A single process already uses both cores (embreex releases the GIL and the hot numba
kernels run in ``prange``); processes are the opt-in alternative (``--workers``). Workers are
spawned (no fork of a process that may hold GL or Embree threads) and each builds its own
scene context once, in ``init``. A few tiles are in flight at a time; closing the consuming
generator cancels the tiles not started.
"""

from __future__ import annotations

import multiprocessing
import os
import sys
import threading
import time
from concurrent.futures import ProcessPoolExecutor
from typing import Callable, Iterator

WATCH_EVERY = 0.25  # seconds between a worker's checks that its parent is alive


def die_with_parent(parent: int, deathsig: bool = True) -> None:
    """In a worker process: end it as soon as ``parent`` is gone (exited, terminated or
    killed). On Linux the kernel sends SIGKILL (prctl PR_SET_PDEATHSIG; only when the parent
    thread that started us is its main thread, since the signal follows that thread); a
    watch thread covers other systems and that case (it needs the GIL, so it may lag a
    GIL-holding kernel). Either way no queue feeder or pool manager is waited for."""
    if deathsig and sys.platform.startswith("linux"):
        try:
            import ctypes
            import signal

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, int(signal.SIGKILL), 0, 0, 0)  # PR_SET_PDEATHSIG
        except (OSError, AttributeError):
            pass
    if os.getppid() != parent:  # gone before the signal was armed
        os._exit(0)

    def watch() -> None:
        while True:
            time.sleep(WATCH_EVERY)
            if os.getppid() != parent:
                os._exit(0)

    threading.Thread(target=watch, name="shadelab-parent-watch", daemon=True).start()


def _watched_init(parent: int, deathsig: bool, init: Callable, init_args: tuple) -> None:
    """Worker start-up: never outlive the main process (a worker blocked on its task queue
    would wait forever, and keep the resource tracker alive), then the caller's ``init``."""
    die_with_parent(parent, deathsig)
    init(*init_args)


def _in_main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


def traced_in_pool(init: Callable, init_args: tuple, task: Callable, jobs: list,
                   task_args: Callable[[tuple], tuple], workers: int) -> Iterator[tuple]:
    """Yield (job, task(*task_args(job))) for each job, in order, from ``workers`` processes."""
    pool = ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"),
                               initializer=_watched_init,
                               initargs=(os.getpid(), _in_main_thread(), init, init_args))
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
        # Ctrl+C or an error: cancel what has not started; a worker mid-tile is ended rather
        # than waited for (its tile is discarded anyway).
        pool.shutdown(wait=False, cancel_futures=True)
        for process in list((getattr(pool, "_processes", None) or {}).values()):
            if process.is_alive() and pending:
                process.terminate()
