"""Offline renders off the UI thread: a generic runner over any ``Iterator[Progress]``.

The renderers (Whitted, path tracer, radiosity) are found lazily, so the viewer runs whether or
not those layers exist yet; a missing one is listed as "not available" with the reason.
Pure module: threads and numpy only, no GL.
"""

from __future__ import annotations

import importlib
import threading
import time
from dataclasses import dataclass
from typing import Callable, Iterator

import numpy as np

from app.progress import Progress
from app.scene.camera import primary_rays
from app.scene.model import Scene
from app.scene.preset import clone_scene

JobFactory = Callable[[Scene, tuple[int, int]], Iterator[Progress]]


class JobRunner:
    """Runs one progressive job in a worker thread; the UI polls ``latest``.

    Cancel sets a flag the worker checks between chunks, then closes the generator, as the
    progress contract asks (chunks stay under 0.2 s, so a cancel lands within one chunk).
    """

    def __init__(self) -> None:
        self.name = ""
        self.latest: Progress | None = None
        self.error = ""
        self.started = 0.0
        self.finished = 0.0
        self.cancelled = False
        self.cancel_requested = 0.0     # perf_counter() of the last cancel
        self.version = 0                # bumps on every new Progress (the UI re-uploads then)
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

    def start(self, name: str, make: Callable[[], Iterator[Progress]]) -> None:
        """Start ``make()``'s generator in a worker; a running job is cancelled first."""
        self.cancel(wait=True)
        self.name, self.latest, self.error, self.cancelled = name, None, "", False
        self.started, self.finished = time.perf_counter(), 0.0
        self._cancel.clear()
        self._thread = threading.Thread(target=self._work, args=(make,), daemon=True,
                                        name=f"shadelab-job-{name}")
        self._thread.start()

    def _work(self, make: Callable[[], Iterator[Progress]]) -> None:
        gen = None
        try:
            gen = make()
            for step in gen:
                with self._lock:
                    self.latest = step
                    self.version += 1
                if self._cancel.is_set():
                    self.cancelled = True
                    break
        except Exception as exc:  # shown in the panel; the UI keeps running
            self.error = f"{type(exc).__name__}: {exc}"
        finally:
            if gen is not None and hasattr(gen, "close"):
                gen.close()
            self.finished = time.perf_counter()

    def cancel(self, wait: bool = False, timeout: float = 5.0) -> None:
        if self.running and not self._cancel.is_set():
            self.cancel_requested = time.perf_counter()
        self._cancel.set()
        if wait and self._thread is not None:
            self._thread.join(timeout)

    def snapshot(self) -> tuple[Progress | None, int]:
        with self._lock:
            return self.latest, self.version


# ---------------------------------------------------------------- the jobs on offer


def iter_reference_raster(scene: Scene, size: tuple[int, int], rows_per_chunk: int = 8):
    """A CPU render with the numpy reference (ray cast + Phong-mode shading), rows at a time.

    Always available: it checks the GPU image pixel for pixel and exercises the job panel.
    """
    from app.geometry.mesh import scene_meshes
    from app.shading.reference import normalize, shade
    from app.ui.probe import _facing, intersect_many

    scene = clone_scene(scene)
    width, height = size
    meshes = scene_meshes(scene)
    origins, directions = primary_rays(scene.camera, width, height)
    image = np.zeros((height, width, 3), np.float32)
    eye = np.asarray(scene.camera.eye, dtype=np.float64)
    for y0 in range(0, height, rows_per_chunk):
        o = origins[y0:y0 + rows_per_chunk].reshape(-1, 3)
        d = directions[y0:y0 + rows_per_chunk].reshape(-1, 3)
        mesh_id, face, t, bary = intersect_many(meshes, o, d)
        out = np.zeros((len(o), 3))
        for m, mesh in enumerate(meshes):
            sel = np.flatnonzero(mesh_id == m)
            if not len(sel):
                continue
            f = face[sel]
            p = o[sel] + t[sel, None] * d[sel]
            n = normalize(np.einsum("ij,ijk->ik", bary[sel], mesh.corner_normals[f]))
            n = _facing(n, mesh.face_normals[f], normalize(eye - p))
            out[sel] = shade(p, n, eye, scene.materials[mesh.material], scene.active_lights(),
                             scene.Ia, scene.render.specular)
        image[y0:y0 + rows_per_chunk] = out.reshape(-1, width, 3)
        done = min(y0 + rows_per_chunk, height)
        yield Progress(image.copy(), done / height, f"rows {done}/{height}")
    yield Progress(image, 1.0, "done", {"pixels": width * height})


@dataclass
class JobKind:
    """One offline renderer the panel offers."""

    label: str
    make: JobFactory | None     # None: not available
    reason: str = ""            # why not, when make is None
    raster_shading: str = "phong"  # the raster view it is compared against


def _lookup(module: str, names: tuple[str, ...]):
    """The first of ``names`` in ``module``, or (None, reason)."""
    try:
        mod = importlib.import_module(module)
    except ImportError as exc:
        return None, f"{module} not available ({exc})"
    for name in names:
        if hasattr(mod, name):
            return getattr(mod, name), ""
    return None, f"{module} has none of {', '.join(names)}"


def _raytrace_factory():
    for module in ("app.raytrace", "app.raytrace.whitted", "app.raytrace.tracer"):
        fn, reason = _lookup(module, ("iter_whitted", "iter_raytrace"))
        if fn is not None:
            return fn, ""
    return None, reason


def _pathtrace_factory(seed: int = 1):
    """The path tracer at the scene's samples per pixel (the panel sets them)."""
    fn, reason = _lookup("app.raytrace.pathtrace", ("iter_pathtrace",))
    if fn is None:
        return None, reason
    return (lambda scene, size: fn(scene, size, max(scene.raytrace.spp, 1), seed)), ""


def _radiosity_factory():
    """Radiosity; GPU hemicube form factors would need a GL context in the worker thread
    (the viewer's context belongs to the UI thread), so the viewer asks for ray-cast ones."""
    for module in ("app.radiosity", "app.radiosity.solver"):
        fn, reason = _lookup(module, ("iter_radiosity",))
        if fn is not None:
            def make(scene, size, fn=fn):
                method = "raycast" if scene.radiosity.form_factors == "hemicube" else None
                return fn(scene, size, form_factors=method)
            return make, ""
    return None, reason


def available_jobs() -> list[JobKind]:
    """The offline renderers, each with a factory or the reason it is missing."""
    kinds = [JobKind("Reference raster (numpy)", iter_reference_raster)]
    for label, (make, reason) in (("Whitted ray tracer", _raytrace_factory()),
                                  ("Path tracer (reference GI)", _pathtrace_factory()),
                                  ("Radiosity", _radiosity_factory())):
        kinds.append(JobKind(label, make, reason, "gouraud" if label == "Radiosity" else "phong"))
    return kinds


def difference(a: np.ndarray, b: np.ndarray) -> dict:
    """Error figures between two linear images of the same shape."""
    diff = np.abs(np.asarray(a, np.float64) - np.asarray(b, np.float64))
    scale = max(float(np.abs(b).max()), 1e-12)
    return {"rmse": float(np.sqrt(np.mean(diff ** 2))), "max_abs": float(diff.max()),
            "relative_rmse": float(np.sqrt(np.mean(diff ** 2)) / scale)}
