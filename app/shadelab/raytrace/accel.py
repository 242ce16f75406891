"""Ray casting against the scene's triangles: Embree (``embreex``) or a numba BVH fallback.

Both backends answer the same two questions over batches of rays (float64 in, world space):

- :meth:`intersect` -> :class:`Hits` (closest hit: distance, triangle, barycentrics u, v with
  ``p = (1 - u - v) p0 + u p1 + v p2``), and
- :meth:`occluded` -> bool (is anything closer than ``tmax``?), against the shadow casters
  only (objects with ``cast_shadows = false``, such as the Cornell light, let shadow rays pass).

Rays start at their origin (t >= 0): callers offset origins off the surface themselves, so the
offset is visible and testable (shadow acne appears when it is 0).
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from shadelab.constants import T_INF  # noqa: F401  (re-exported: accel.T_INF)
from shadelab.geometry.mesh import MeshData, scene_meshes
from shadelab.raytrace import BACKENDS  # noqa: F401  (re-exported: accel.BACKENDS)
from shadelab.scene.model import Scene


@dataclass
class SceneGeometry:
    """Every triangle of the scene in one flat array, with what a shader needs per triangle.

    Attributes
    ----------
    triangles : (F, 3, 3) float64 corner positions, world space
    face_normals : (F, 3) float64, unit, counter-clockwise front
    corner_normals : (F, 3, 3) float64, unit, by each object's normals mode
    object_index : (F,) int64, index into ``scene.objects``
    casts_shadow : (F,) bool, the object's ``cast_shadows``
    diagonal : length of the scene's bounding-box diagonal, world units
    corner_uvs : (F, 3, 2) float64 texture coordinates of the corners (the raster's uvs)
    """

    triangles: np.ndarray
    face_normals: np.ndarray
    corner_normals: np.ndarray
    object_index: np.ndarray
    casts_shadow: np.ndarray
    diagonal: float
    corner_uvs: np.ndarray | None = None

    @property
    def count(self) -> int:
        return len(self.triangles)


def scene_geometry(scene: Scene, meshes: list[MeshData] | None = None) -> SceneGeometry:
    """Flatten the scene's meshes (the same triangles the raster draws)."""
    meshes = scene_meshes(scene) if meshes is None else meshes
    if not meshes or sum(len(m.faces) for m in meshes) == 0:
        empty3 = np.zeros((0, 3, 3))
        return SceneGeometry(empty3, np.zeros((0, 3)), empty3, np.zeros(0, np.int64),
                             np.zeros(0, bool), 1.0, np.zeros((0, 3, 2)))
    triangles = np.concatenate([m.triangles for m in meshes])
    face_n = np.concatenate([m.face_normals for m in meshes])
    corner_n = np.concatenate([m.corner_normals for m in meshes])
    corner_uv = np.concatenate([np.asarray(m.uvs, np.float64)[m.faces] for m in meshes])
    object_index = np.concatenate([np.full(len(m.faces), m.index, np.int64) for m in meshes])
    casts = np.array([scene.objects[i].cast_shadows for i in range(len(scene.objects))], bool)
    lo = triangles.reshape(-1, 3).min(axis=0)
    hi = triangles.reshape(-1, 3).max(axis=0)
    diagonal = float(np.linalg.norm(hi - lo)) or 1.0
    return SceneGeometry(triangles, face_n, corner_n, object_index, casts[object_index], diagonal,
                         corner_uv)


@dataclass
class Hits:
    """Closest hits of a batch of N rays; ``tri`` is -1 (and ``t`` is inf) for a miss."""

    t: np.ndarray    # (N,) float64 distance along the unit direction
    tri: np.ndarray  # (N,) int64 triangle index into SceneGeometry
    u: np.ndarray    # (N,) float64 barycentric weight of corner 1
    v: np.ndarray    # (N,) float64 barycentric weight of corner 2

    @property
    def hit(self) -> np.ndarray:
        return self.tri >= 0


SPLIT_RAYS = 16384  # a batch this long or longer is split across threads


def accel_threads() -> int:
    """Threads an Embree batch is split over: the cores this process may run on
    (``SHADELAB_THREADS`` overrides; 1 traces in the calling thread)."""
    env = os.environ.get("SHADELAB_THREADS", "")
    if env.strip().isdigit() and int(env) >= 1:
        return int(env)
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not Linux
        return max(1, os.cpu_count() or 1)


_POOL: ThreadPoolExecutor | None = None


def _pool() -> ThreadPoolExecutor:
    global _POOL
    if _POOL is None:
        _POOL = ThreadPoolExecutor(max_workers=accel_threads(),
                                   thread_name_prefix="shadelab-embree")
    return _POOL


def _embree_run(target, o32: np.ndarray, d32: np.ndarray, dists: np.ndarray | None,
                query: str, output: bool):
    """``target.run`` over the batch, in slices on the pool's threads where it is long
    (embreex releases the GIL around its ray loop; each slice is an independent query of the
    committed scene, so the answer is the same ray for ray)."""
    n = len(o32)
    threads = accel_threads()
    if threads <= 1 or n < SPLIT_RAYS:
        return target.run(o32, d32, dists=dists, query=query, output=output)
    bounds = np.linspace(0, n, threads + 1).astype(np.int64)
    futures = [_pool().submit(target.run, o32[a:b], d32[a:b],
                              None if dists is None else dists[a:b], query, output)
               for a, b in zip(bounds[:-1], bounds[1:], strict=True) if b > a]
    parts = [f.result() for f in futures]
    if output:
        return {key: np.concatenate([p[key] for p in parts])
                for key in ("primID", "u", "v", "tfar")}
    return np.concatenate(parts)


class EmbreeAccel:
    """Embree 4 through embreex: one scene of all triangles, one of the shadow casters.

    Long batches are traced on :func:`accel_threads` threads (see :func:`_embree_run`).
    """

    name = "embree"

    def __init__(self, geometry: SceneGeometry):
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh

        self.geometry = geometry
        self._scratch: dict[str, np.ndarray] = {}
        self._all = rtcore_scene.EmbreeScene()
        self._casters = rtcore_scene.EmbreeScene()
        tris = geometry.triangles.astype(np.float32)
        self._caster_ids = np.flatnonzero(geometry.casts_shadow)
        if len(tris):
            TriangleMesh(self._all, tris)
        if len(self._caster_ids):
            TriangleMesh(self._casters, tris[self._caster_ids])
        # Commit both scenes now (embreex commits on the first query), before any threads
        one = np.zeros((1, 3), np.float32)
        for scene in (self._all, self._casters):
            scene.run(one, one + np.float32(1.0), query="OCCLUDED", dists=np.zeros(1, np.float32))

    def _float32(self, name: str, a: np.ndarray) -> np.ndarray:
        """``a`` as C-contiguous float32, converted into a buffer kept for the next batch."""
        if a.dtype == np.float32 and a.flags.c_contiguous:
            return a
        buf = self._scratch.get(name)
        if buf is None or buf.shape[0] < len(a):
            buf = self._scratch[name] = np.empty((max(len(a), 1024), 3), np.float32)
        out = buf[:len(a)]
        np.copyto(out, a, casting="same_kind")
        return out

    def intersect_raw(self, origins: np.ndarray, dirs: np.ndarray,
                      tmax: np.ndarray | None = None):
        """Closest hits as Embree gives them: tfar (float32), primID (int32, -1 for a miss),
        u, v (float32); :meth:`intersect` converts these to a :class:`Hits`. Not for two
        threads at once on one accelerator (the float32 copies of the rays are reused)."""
        o = self._float32("o", origins)
        d = self._float32("d", dirs)
        dists = None if tmax is None else np.ascontiguousarray(
            np.minimum(tmax, T_INF), dtype=np.float32)
        out = _embree_run(self._all, o, d, dists, "INTERSECT", True)
        return out["tfar"], out["primID"], out["u"], out["v"]

    def intersect(self, origins: np.ndarray, dirs: np.ndarray,
                  tmax: np.ndarray | None = None) -> Hits:
        n = len(origins)
        if n == 0 or self.geometry.count == 0:
            return _misses(n)
        tfar, prim, u, v = self.intersect_raw(origins, dirs, tmax)
        tri = prim.astype(np.int64)
        hit = tri >= 0
        t = np.where(hit, tfar.astype(np.float64), np.inf)
        return Hits(t, tri, u.astype(np.float64), v.astype(np.float64))

    def occluder(self, faces: np.ndarray) -> Occluder:
        """Occlusion queries against the triangles ``faces`` alone (a scene of their own)."""
        from embreex import rtcore_scene
        from embreex.mesh_construction import TriangleMesh

        scene = rtcore_scene.EmbreeScene()
        faces = np.asarray(faces, dtype=np.int64)
        if len(faces):
            TriangleMesh(scene, self.geometry.triangles[faces].astype(np.float32))
            one = np.zeros((1, 3), np.float32)   # commit now, before any threads
            scene.run(one, one + np.float32(1.0), query="OCCLUDED", dists=np.zeros(1, np.float32))

        def query(origins, dirs, tmax):
            n = len(origins)
            o = np.ascontiguousarray(origins, dtype=np.float32)
            d = np.ascontiguousarray(dirs, dtype=np.float32)
            dists = np.ascontiguousarray(np.minimum(np.broadcast_to(tmax, (n,)), T_INF),
                                         dtype=np.float32)
            return _embree_run(scene, o, d, dists, "OCCLUDED", False) != -1
        return Occluder(len(faces), query)

    def occluded(self, origins: np.ndarray, dirs: np.ndarray, tmax: np.ndarray,
                 everything: bool = False) -> np.ndarray:
        """True where a shadow caster (any triangle with ``everything``) lies at t < tmax."""
        n = len(origins)
        target = self._all if everything else self._casters
        if n == 0 or (self.geometry.count if everything else len(self._caster_ids)) == 0:
            return np.zeros(n, bool)
        o = np.ascontiguousarray(origins, dtype=np.float32)
        d = np.ascontiguousarray(dirs, dtype=np.float32)
        dists = np.ascontiguousarray(np.minimum(np.broadcast_to(tmax, (n,)), T_INF),
                                     dtype=np.float32)
        return _embree_run(target, o, d, dists, "OCCLUDED", False) != -1


class Occluder:
    """Occlusion queries against a subset of the scene's triangles (:meth:`EmbreeAccel.occluder`,
    :meth:`BvhAccel.occluder`); with no triangles nothing is occluded."""

    def __init__(self, count: int, query) -> None:
        self.count, self._query = count, query

    def occluded(self, origins: np.ndarray, dirs: np.ndarray, tmax: np.ndarray) -> np.ndarray:
        """True where one of the subset's triangles lies at t < tmax."""
        if len(origins) == 0 or self.count == 0:
            return np.zeros(len(origins), bool)
        return self._query(origins, dirs, tmax)


def _misses(n: int) -> Hits:
    return Hits(np.full(n, np.inf), np.full(n, -1, np.int64), np.zeros(n), np.zeros(n))


class BvhAccel:
    """The numba BVH (see :mod:`shadelab.raytrace.bvh`): same answers, no Embree needed."""

    name = "bvh"

    def __init__(self, geometry: SceneGeometry):
        from shadelab.raytrace import bvh

        self.geometry = geometry
        self._bvh = bvh
        self._all = bvh.build(geometry.triangles)
        self._caster_ids = np.flatnonzero(geometry.casts_shadow)
        self._casters = bvh.build(geometry.triangles[self._caster_ids])

    def intersect(self, origins: np.ndarray, dirs: np.ndarray,
                  tmax: np.ndarray | None = None) -> Hits:
        n = len(origins)
        if n == 0 or self.geometry.count == 0:
            return _misses(n)
        limit = np.full(n, T_INF) if tmax is None else np.minimum(
            np.broadcast_to(tmax, (n,)), T_INF).astype(np.float64)
        t, tri, u, v = self._bvh.intersect(self._all, np.ascontiguousarray(origins, np.float64),
                                           np.ascontiguousarray(dirs, np.float64), limit)
        return Hits(np.where(tri >= 0, t, np.inf), tri, u, v)

    def intersect_raw(self, origins: np.ndarray, dirs: np.ndarray,
                      tmax: np.ndarray | None = None):
        """(t, tri, u, v) as :meth:`EmbreeAccel.intersect_raw` (float64 and int64 here)."""
        hits = self.intersect(origins, dirs, tmax)
        return hits.t, hits.tri, hits.u, hits.v

    def occluded(self, origins: np.ndarray, dirs: np.ndarray, tmax: np.ndarray,
                 everything: bool = False) -> np.ndarray:
        """True where a shadow caster (any triangle with ``everything``) lies at t < tmax."""
        n = len(origins)
        if n == 0 or (self.geometry.count if everything else len(self._caster_ids)) == 0:
            return np.zeros(n, bool)
        limit = np.minimum(np.broadcast_to(tmax, (n,)), T_INF).astype(np.float64)
        tree = self._all if everything else self._casters
        return self._bvh.occluded(tree, np.ascontiguousarray(origins, np.float64),
                                  np.ascontiguousarray(dirs, np.float64), limit)

    def occluder(self, faces: np.ndarray) -> Occluder:
        """Occlusion queries against the triangles ``faces`` alone (a tree of their own)."""
        faces = np.asarray(faces, dtype=np.int64)
        tree = self._bvh.build(self.geometry.triangles[faces]) if len(faces) else None

        def query(origins, dirs, tmax):
            n = len(origins)
            limit = np.minimum(np.broadcast_to(tmax, (n,)), T_INF).astype(np.float64)
            return self._bvh.occluded(tree, np.ascontiguousarray(origins, np.float64),
                                      np.ascontiguousarray(dirs, np.float64), limit)
        return Occluder(len(faces), query)


def embree_available() -> bool:
    try:
        import embreex.mesh_construction  # noqa: F401
        import embreex.rtcore_scene  # noqa: F401
    except ImportError:
        return False
    return True


def build_accel(geometry: SceneGeometry, backend: str = "auto"):
    """An :class:`EmbreeAccel` where embreex imports (``auto``), else a :class:`BvhAccel`."""
    if backend not in BACKENDS:
        raise ValueError(f"unknown backend {backend!r}")
    if backend == "embree" or (backend == "auto" and embree_available()):
        return EmbreeAccel(geometry)
    return BvhAccel(geometry)
