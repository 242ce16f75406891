"""Offline renders off the UI thread: a generic runner over any ``Iterator[Progress]``.

A job whose factory can be pickled (every renderer on offer) runs in a worker *process*, so
numba compilation or a GIL-holding kernel never stalls the UI, and a cancel that does not land
within ``KILL_AFTER`` seconds ends the process; anything else (a closure, a test's generator)
runs in a worker thread. Either way the UI polls :meth:`JobRunner.snapshot`.

The jobs on offer are the pipelines of :mod:`shadelab.pipelines` that have a ``job_label``
(:func:`available_jobs`); :meth:`JobRunner.start_pipeline` starts one by its registry name.
Pure module: threads, processes and numpy only, no GL.
"""

from __future__ import annotations

import importlib
import multiprocessing
import os
import pickle
import queue
import sys
import threading
import time
from dataclasses import dataclass
from typing import Callable, Iterator

import numpy as np

from shadelab.progress import Progress
from shadelab.scene.model import Scene
from shadelab.scene.preset import clone_scene

JobFactory = Callable[[Scene, tuple[int, int]], Iterator[Progress]]
KILL_AFTER = 3.0   # seconds a cancelled process job may take before its process is ended
PREPARE_EVERY_S = 0.25   # while images keep coming, the newest is prepared this often
TRAIL_MAX = 4096   # Progress entries a job keeps in its trail (a test and the log read it)


def _picklable(step: Progress) -> Progress:
    """The Progress itself, or a copy without the stats entries that cannot cross processes.

    Only the small parts are test-pickled (message, fraction, stats): the image, a numpy array
    (~11 MB at full viewport size), is pickled once, by the queue that sends it."""
    image = step.image
    try:
        pickle.dumps((step.fraction, step.message, step.stats,
                      None if image is None or type(image) is np.ndarray else image))
        return step
    except Exception:
        stats = {}
        for key, value in (step.stats or {}).items():
            try:
                pickle.dumps(value)
                stats[key] = value
            except Exception:
                stats[key] = f"<{type(value).__name__}>"
        return Progress(image, step.fraction, step.message, stats)


def _process_main(tasks, results, cancel, parent: int | None = None,
                  deathsig: bool = False) -> None:
    """The worker process: run each (job_id, factory, scene, size) task, streaming Progress.
    It ends as soon as the viewer is gone (exited, terminated or killed; see
    :func:`shadelab.raytrace.pool.die_with_parent`), even in the middle of a job."""
    import os

    from shadelab.raytrace.pool import die_with_parent

    parent = os.getppid() if parent is None else parent
    die_with_parent(parent, deathsig)
    results.cancel_join_thread()  # exiting never waits for a reader that is gone
    while True:
        try:
            task = tasks.get(timeout=1.0)
        except queue.Empty:
            if os.getppid() != parent:
                return  # the viewer is gone (crashed or killed): do not linger
            continue
        if task is None:
            return
        job_id, factory, scene, size = task
        gen, error, cancelled = None, "", False
        try:
            gen = factory(scene, size)
            for step in gen:
                results.put(("progress", job_id, _picklable(step)))
                if cancel.is_set():
                    cancelled = True
                    break
        except Exception as exc:
            error = f"{type(exc).__name__}: {exc}"
        finally:
            if gen is not None and hasattr(gen, "close"):
                gen.close()
        results.put(("done", job_id, error, cancelled))


class WorkerProcess:
    """One long-lived spawned process that runs jobs one at a time (started on first use)."""

    spawns = 0   # processes started, every WorkerProcess together (a test counts them)

    def __init__(self) -> None:
        self._mp = multiprocessing.get_context("spawn")
        self.process = None
        self.tasks = self.results = self.cancel = None

    def ensure(self) -> None:
        if self.process is not None and self.process.is_alive():
            return
        self.tasks, self.results = self._mp.Queue(), self._mp.Queue()
        self.cancel = self._mp.Event()
        self.process = self._mp.Process(target=_process_main, name="shadelab-jobs", daemon=True,
                                        args=(self.tasks, self.results, self.cancel,
                                              os.getpid(), threading.current_thread()
                                              is threading.main_thread()))
        # A spawned child re-imports the parent's __main__ (here ``shadelab/__main__.py``, which
        # would start another viewer); hide it while the child's start-up data is taken.
        main = sys.modules.get("__main__")
        saved = {k: main.__dict__[k] for k in ("__spec__", "__file__") if k in main.__dict__}
        try:
            main.__spec__ = None
            main.__dict__.pop("__file__", None)
            self.process.start()
            WorkerProcess.spawns += 1
        finally:
            main.__dict__.update(saved)

    def warm(self) -> None:
        """Start the process and import the renderers in it ahead of the first job."""
        self.ensure()
        self.tasks.put((0, warm_up, None, None))

    def kill(self) -> None:
        # taken first: the job thread and the window's exit may both end the worker (the
        # exit once found self.process None between the two is_alive checks)
        process, self.process = self.process, None
        if process is not None and process.is_alive():
            process.terminate()
            process.join(1.0)
            if process.is_alive():  # SIGTERM not taken within a second: SIGKILL
                process.kill()
                process.join(0.5)

    def shutdown(self) -> None:
        """End the worker within ~2 s: ask (cancel the job, then the end-of-tasks mark),
        then terminate, then kill."""
        if self.process is not None and self.process.is_alive():
            self.cancel.set()
            self.tasks.put(None)
            self.process.join(0.5)
        self.kill()


class JobRunner:
    """Runs one progressive job in a worker thread; the UI polls ``latest``.

    Cancel sets a flag the worker checks between chunks, then closes the generator, as the
    progress contract asks (chunks stay under 0.2 s, so a cancel lands within one chunk).
    """

    def __init__(self, use_process: bool = True) -> None:
        self.use_process = use_process
        self.worker = WorkerProcess() if use_process else None
        self.in_process = False         # the current job runs in the worker process
        self._job_id = 0
        self.name = ""
        self.latest: Progress | None = None
        self.error = ""
        self.started = 0.0
        self.finished = 0.0
        self.cancelled = False
        self.cancel_requested = 0.0     # perf_counter() of the last cancel
        self.kill_after: float | None = KILL_AFTER   # of that cancel (None: never killed)
        self.version = 0                # bumps on every new Progress (the UI re-uploads then)
        self.trail: list[dict] = []     # every Progress of the job, in brief (the UI may skip some)
        self.rows: dict = {}            # rows of a matrix the job sends in pieces, every piece
        #                                 kept (stats["ff_rows"]: radiosity's form factors)
        # the UI's per-image work, done in the listener thread for the newest image (numpy
        # frees the GIL: the UI thread keeps drawing): (version, value, stats, message)
        self.prepare: Callable[[Progress], object] | None = None
        self.prepared: tuple | None = None
        self._prepared_at = 0.0
        self._cancel = threading.Event()
        self._thread: threading.Thread | None = None
        self._lock = threading.Lock()

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    @property
    def elapsed(self) -> float:
        """Seconds since the job started (frozen when it ends)."""
        if not self.started:
            return 0.0
        return (self.finished or time.perf_counter()) - self.started

    def start(self, name: str, make: Callable[[], Iterator[Progress]],
              call: tuple | None = None) -> None:
        """Start a job; a running one is cancelled first.

        ``call`` = (factory, scene, size) runs ``factory(scene, size)`` in the worker process
        when it pickles; otherwise ``make()``'s generator runs in a thread.
        """
        self.cancel(wait=True)
        self.name, self.latest, self.error, self.cancelled = name, None, "", False
        self.trail, self.rows, self.prepared = [], {}, None
        self.started, self.finished = time.perf_counter(), 0.0
        self._cancel.clear()
        self._job_id += 1
        self.in_process = bool(self.use_process and call is not None and _pickles(call))
        if self.in_process:
            self.worker.ensure()
            self.worker.cancel.clear()
            self.worker.tasks.put((self._job_id, *call))
            target, args = self._listen, (self._job_id,)
        else:
            target, args = self._work, (make,)
        self._thread = threading.Thread(target=target, args=args, daemon=True,
                                        name=f"shadelab-job-{name}")
        self._thread.start()

    def start_pipeline(self, name: str, scene: Scene, size: tuple[int, int],
                       viewport: bool = False) -> None:
        """Start registry pipeline ``name``'s job (``viewport``: its coarse-to-fine job) on a
        copy of ``scene``; a pipeline the worker process cannot look up runs in a thread."""
        from functools import partial

        from shadelab import pipelines

        pipeline = pipelines.get(name)
        scene = clone_scene(scene)
        factory = partial(pipelines.viewport_job if viewport else pipelines.run_job, name)
        if not _pickles(pipeline):
            def factory(scene, size, p=pipeline):  # noqa: F811
                return p.viewport_job(scene, size) if viewport else p.job(scene, size)
        self.start(name, lambda: factory(scene, size), call=(factory, scene, size))

    def _publish(self, step: Progress) -> None:
        """Make ``step`` the newest Progress (under the lock) and note it in the trail."""
        self.latest = step
        self.version += 1
        rows = (step.stats or {}).get("ff_rows") if isinstance(step.stats, dict) else None
        if rows is not None and len(rows) == 2 and len(rows[0]) == len(rows[1]):
            self.rows.update(zip((int(i) for i in rows[0]), rows[1], strict=True))
        if len(self.trail) < TRAIL_MAX:
            stats = step.stats or {}
            self.trail.append({"fraction": float(step.fraction), "level": stats.get("level"),
                               "done": bool(stats.get("done"))})

    def _listen(self, job_id: int) -> None:
        """Relay the worker process's Progress; end it if a cancel does not land in time."""
        worker = self.worker
        while True:
            if self._cancel.is_set() and self.kill_after is not None \
                    and time.perf_counter() - self.cancel_requested > self.kill_after:
                worker.kill()
                self.cancelled = True
                break
            if not worker.process or not worker.process.is_alive():
                self.error = self.error or "the job's worker process ended unexpectedly"
                break
            try:
                message = worker.results.get(timeout=0.05)
            except queue.Empty:
                continue
            if message[1] != job_id:
                continue  # a late message of an earlier job
            if message[0] == "progress":
                with self._lock:
                    self._publish(message[2])
                # the newest image once the queue is drained (or every PREPARE_EVERY_S while
                # images keep coming): never a backlog of conversions behind the worker
                if self.prepare is not None and (
                        worker.results.empty()
                        or time.perf_counter() - self._prepared_at > PREPARE_EVERY_S):
                    self._prepare_latest()
            else:
                self.error, self.cancelled = message[2], message[3]
                break
        if self.prepare is not None:   # the last image, whatever the queue held after it
            self._prepare_latest()
        self.finished = time.perf_counter()

    def _prepare_latest(self) -> None:
        """``prepare`` the newest Progress's image, outside the lock; ``prepared`` then holds
        (its version, the result, its stats, its message)."""
        with self._lock:
            step, version = self.latest, self.version
        if step is None or step.image is None or (
                self.prepared is not None and self.prepared[0] == version):
            return
        self._prepared_at = time.perf_counter()
        try:
            value = self.prepare(step)
        except Exception:   # the UI thread converts it instead
            return
        self.prepared = (version, value, step.stats or {}, step.message)

    def _work(self, make: Callable[[], Iterator[Progress]]) -> None:
        gen = None
        try:
            gen = make()
            for step in gen:
                with self._lock:
                    self._publish(step)
                if self._cancel.is_set():
                    self.cancelled = True
                    break
        except Exception as exc:  # shown in the panel; the UI keeps running
            self.error = f"{type(exc).__name__}: {exc}"
        finally:
            if gen is not None and hasattr(gen, "close"):
                gen.close()
            self.finished = time.perf_counter()

    def cancel(self, wait: bool = False, timeout: float = 5.0,
               kill_after: float | None = KILL_AFTER) -> None:
        """Stop the job at its next Progress; a process job that has not stopped
        ``kill_after`` seconds later has its worker ended (None: never, it stops at its next
        step however long that takes, e.g. a kernel warm-up that must not die mid-compile)."""
        if self.running and not self._cancel.is_set():
            self.cancel_requested = time.perf_counter()
        self.kill_after = kill_after
        self._cancel.set()
        if self.in_process and self.worker.cancel is not None:
            self.worker.cancel.set()
        if wait and self._thread is not None:
            self._thread.join(timeout)

    def shutdown(self) -> None:
        """Cancel the job and end the worker process (the viewer is closing)."""
        self.cancel(wait=True, timeout=1.0)
        if self.worker is not None:
            self.worker.shutdown()

    def snapshot(self) -> tuple[Progress | None, int]:
        with self._lock:
            return self.latest, self.version


# ---------------------------------------------------------------- the jobs on offer

from shadelab.pipelines.reference import iter_reference_raster  # noqa: E402,F401


@dataclass
class JobKind:
    """One offline renderer the panel offers."""

    label: str
    make: JobFactory | None     # None: not available
    reason: str = ""            # why not, when make is None
    raster_shading: str = "phong"  # the raster view it is compared against
    pipeline: str = ""          # its name in shadelab.pipelines ("" for a test's own job)
    samples: bool = False       # it takes the scene's samples per pixel (the panel's slider)


def _pickles(value) -> bool:
    try:
        pickle.dumps(value)
        return True
    except Exception:
        return False


def warm_up(scene, size) -> Iterator[Progress]:
    """Import every renderer (numba caches load, embree starts); yields nothing."""
    for module in ("shadelab.raytrace.whitted", "shadelab.raytrace.pathtrace",
                   "shadelab.radiosity.solution"):
        try:
            importlib.import_module(module)
        except ImportError:
            pass
    return iter(())


def job_kind(pipeline) -> JobKind:
    """The panel's entry for a registry pipeline: its job, picklable by name for built-ins."""
    from functools import partial

    from shadelab.pipelines import run_job

    make = partial(run_job, pipeline.name) if _pickles(pipeline) else \
        (lambda scene, size, p=pipeline: p.job(scene, size))
    return JobKind(pipeline.job_label, make, "", pipeline.compare_shading, pipeline.name,
                   bool(getattr(pipeline, "samples_setting", False)))


def available_jobs() -> list[JobKind]:
    """The offline renderers of :mod:`shadelab.pipelines` that offer a job, in panel order
    (a pipeline registered later, e.g. by a test, is listed too)."""
    from shadelab import pipelines

    return [job_kind(p) for p in pipelines.job_pipelines()]


def find_job(name: str) -> JobKind | None:
    """The job of pipeline ``name``, or of the first label starting with ``name`` (--job)."""
    kinds = available_jobs()
    for kind in kinds:
        if kind.pipeline == name:
            return kind
    for kind in kinds:
        if name.strip() and kind.label.lower().startswith(name.lower()):
            return kind
    return None


def difference(a: np.ndarray, b: np.ndarray) -> dict:
    """Error figures between two linear images of the same shape."""
    diff = np.abs(np.asarray(a, np.float64) - np.asarray(b, np.float64))
    scale = max(float(np.abs(b).max()), 1e-12)
    return {"rmse": float(np.sqrt(np.mean(diff ** 2))), "max_abs": float(diff.max()),
            "relative_rmse": float(np.sqrt(np.mean(diff ** 2)) / scale)}
