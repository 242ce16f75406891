"""A plain bounding-volume hierarchy in numba: the fallback where embreex is missing.

Median split on the longest centroid axis (built in numpy), up to ``LEAF_SIZE`` triangles
per leaf; rays are traversed in parallel (``prange``) with a per-ray stack, Moller-Trumbore
tests in float64.
The barycentric convention matches Embree's: ``p = (1 - u - v) p0 + u p1 + v p2``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba as nb
import numpy as np

LEAF_SIZE = 4      # triangles per leaf
STACK_SIZE = 64    # traversal stack entries per ray (depth of a median-split tree of 2^60)


@dataclass
class Bvh:
    """Flattened tree: inner nodes have ``count == 0`` and children ``a``, ``b``;
    leaves hold ``prims[a : a + count]``."""

    lo: np.ndarray      # (M, 3) float64 box minimum
    hi: np.ndarray      # (M, 3) float64 box maximum
    a: np.ndarray       # (M,) int64 left child, or first primitive slot of a leaf
    b: np.ndarray       # (M,) int64 right child
    count: np.ndarray   # (M,) int64 primitives in a leaf, 0 for an inner node
    prims: np.ndarray   # (F,) int64 triangle indices in leaf order
    v0: np.ndarray      # (F, 3) float64 corners
    e1: np.ndarray      # (F, 3) float64 p1 - p0
    e2: np.ndarray      # (F, 3) float64 p2 - p0


def _build(tri_lo: np.ndarray, tri_hi: np.ndarray, centroids: np.ndarray, leaf_size: int):
    """Median-split build in numpy (a few thousand nodes: fast enough, and nothing to JIT)."""
    n = len(centroids)
    cap = max(2 * n, 1)
    lo = np.zeros((cap, 3))
    hi = np.zeros((cap, 3))
    a = np.zeros(cap, np.int64)
    b = np.zeros(cap, np.int64)
    count = np.zeros(cap, np.int64)
    prims = np.arange(n)
    stack = [(0, 0, n)]  # node, start, end
    used = 1
    while stack:
        node, start, end = stack.pop()
        members = prims[start:end]
        # Bound the node's triangles
        lo[node] = tri_lo[members].min(axis=0)
        hi[node] = tri_hi[members].max(axis=0)
        if end - start <= leaf_size:
            a[node], count[node] = start, end - start
            continue
        # Split at the median along the longest centroid axis
        c = centroids[members]
        axis = int(np.argmax(c.max(axis=0) - c.min(axis=0)))
        mid = (end - start) // 2
        order = np.argpartition(c[:, axis], mid)
        prims[start:end] = members[order]
        left, right = used, used + 1
        used += 2
        a[node], b[node], count[node] = left, right, 0
        stack.append((left, start, start + mid))
        stack.append((right, start + mid, end))
    return lo[:used], hi[:used], a[:used], b[:used], count[:used], prims


def build(triangles: np.ndarray) -> Bvh:
    """A BVH over (F, 3, 3) triangles (F may be 0: every ray misses)."""
    tris = np.ascontiguousarray(triangles, dtype=np.float64).reshape(-1, 3, 3)
    if len(tris) == 0:
        z3, z = np.zeros((1, 3)), np.zeros(1, np.int64)
        return Bvh(z3 + np.inf, z3 - np.inf, z, z, z, np.zeros(0, np.int64),
                   np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)))
    lo, hi, a, b, count, prims = _build(tris.min(axis=1), tris.max(axis=1), tris.mean(axis=1),
                                        LEAF_SIZE)
    ordered = tris[prims]
    return Bvh(lo, hi, a, b, count, prims, np.ascontiguousarray(ordered[:, 0]),
               np.ascontiguousarray(ordered[:, 1] - ordered[:, 0]),
               np.ascontiguousarray(ordered[:, 2] - ordered[:, 0]))


@nb.njit(cache=True, inline="always")
def _box_entry(lo, hi, node, o, inv):
    """Distance at which the ray enters the node's box, or inf where it misses."""
    t0 = 0.0
    t1 = np.inf
    for k in range(3):
        ta = (lo[node, k] - o[k]) * inv[k]
        tb = (hi[node, k] - o[k]) * inv[k]
        if ta > tb:
            ta, tb = tb, ta
        if ta != ta:  # 0 * inf: the ray lies in the slab's plane
            ta = -np.inf
        if tb != tb:
            tb = np.inf
        t0 = max(t0, ta)
        t1 = min(t1, tb)
    return t0 if t0 <= t1 else np.inf


@nb.njit(cache=True)
def _trace_one(lo, hi, a, b, count, v0, e1, e2, o, d, tmax, any_hit):
    """Closest (or any) hit of one ray: slot in leaf order, t, u, v (slot -1 for a miss)."""
    inv = np.empty(3)
    for k in range(3):
        inv[k] = 1.0 / d[k] if d[k] != 0.0 else np.copysign(np.inf, d[k])
    stack = np.empty(STACK_SIZE, np.int64)
    stack[0] = 0
    top = 1
    best_t, best_slot, best_u, best_v = tmax, -1, 0.0, 0.0
    while top > 0:
        top -= 1
        node = stack[top]
        if _box_entry(lo, hi, node, o, inv) >= best_t:
            continue
        if count[node] == 0:
            stack[top] = a[node]
            stack[top + 1] = b[node]
            top += 2
            continue
        for s in range(a[node], a[node] + count[node]):
            # Moller-Trumbore, two-sided
            px = d[1] * e2[s, 2] - d[2] * e2[s, 1]
            py = d[2] * e2[s, 0] - d[0] * e2[s, 2]
            pz = d[0] * e2[s, 1] - d[1] * e2[s, 0]
            det = e1[s, 0] * px + e1[s, 1] * py + e1[s, 2] * pz
            if det == 0.0:
                continue
            inv_det = 1.0 / det
            tx, ty, tz = o[0] - v0[s, 0], o[1] - v0[s, 1], o[2] - v0[s, 2]
            u = (tx * px + ty * py + tz * pz) * inv_det
            if u < 0.0 or u > 1.0:
                continue
            qx = ty * e1[s, 2] - tz * e1[s, 1]
            qy = tz * e1[s, 0] - tx * e1[s, 2]
            qz = tx * e1[s, 1] - ty * e1[s, 0]
            v = (d[0] * qx + d[1] * qy + d[2] * qz) * inv_det
            if v < 0.0 or u + v > 1.0:
                continue
            t = (e2[s, 0] * qx + e2[s, 1] * qy + e2[s, 2] * qz) * inv_det
            if t > 0.0 and t < best_t:
                best_t, best_slot, best_u, best_v = t, s, u, v
                if any_hit:
                    return best_slot, best_t, best_u, best_v
    return best_slot, best_t, best_u, best_v


@nb.njit(cache=True, parallel=True)
def _intersect(lo, hi, a, b, count, prims, v0, e1, e2, origins, dirs, tmax):
    n = len(origins)
    t_out = np.full(n, np.inf)
    tri_out = np.full(n, -1, np.int64)
    u_out = np.zeros(n)
    v_out = np.zeros(n)
    for i in nb.prange(n):
        slot, t, u, v = _trace_one(lo, hi, a, b, count, v0, e1, e2, origins[i], dirs[i],
                                   tmax[i], False)
        if slot >= 0:
            t_out[i], tri_out[i], u_out[i], v_out[i] = t, prims[slot], u, v
    return t_out, tri_out, u_out, v_out


@nb.njit(cache=True, parallel=True)
def _occluded(lo, hi, a, b, count, v0, e1, e2, origins, dirs, tmax):
    n = len(origins)
    out = np.zeros(n, np.bool_)
    for i in nb.prange(n):
        slot, _, _, _ = _trace_one(lo, hi, a, b, count, v0, e1, e2, origins[i], dirs[i],
                                   tmax[i], True)
        out[i] = slot >= 0
    return out


def intersect(bvh: Bvh, origins: np.ndarray, dirs: np.ndarray, tmax: np.ndarray):
    """Closest hits: (t, triangle index or -1, u, v), each (N,)."""
    if len(bvh.prims) == 0:
        n = len(origins)
        return np.full(n, np.inf), np.full(n, -1, np.int64), np.zeros(n), np.zeros(n)
    return _intersect(bvh.lo, bvh.hi, bvh.a, bvh.b, bvh.count, bvh.prims, bvh.v0, bvh.e1,
                      bvh.e2, origins, dirs, np.ascontiguousarray(tmax, np.float64))


def occluded(bvh: Bvh, origins: np.ndarray, dirs: np.ndarray, tmax: np.ndarray) -> np.ndarray:
    """True where some triangle lies at 0 < t < tmax."""
    if len(bvh.prims) == 0:
        return np.zeros(len(origins), bool)
    return _occluded(bvh.lo, bvh.hi, bvh.a, bvh.b, bvh.count, bvh.v0, bvh.e1, bvh.e2,
                     origins, dirs, np.ascontiguousarray(tmax, np.float64))
