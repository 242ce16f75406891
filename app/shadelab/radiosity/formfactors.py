"""Form factors F_ij: the share of the energy leaving patch i that arrives at patch j.

Three ways, as in the lecture and the literature:

* ``analytic`` -- unoccluded. The exact point-to-polygon form factor (Lambert / ARCHITECTURE.md §5)

      F(dA_x -> A_j) = (1 / 2 pi) |sum_k gamma_k n_x . (R_k x R_k+1) / |R_k x R_k+1||

  integrated over patch i with a 2x2 Gauss-Legendre rule on the patch's bilinear map
  (Baum, Rushmeier & Winget 1989 recommend the exact kernel over the disk approximation).
* ``raycast`` -- Wallace, Elmquist & Haines 1989: from each receiving point, rays to sample
  points on the source decide visibility (embreex), each ray weighted by Wallace's disk term
  ``cos_i cos_j dA / (pi r^2 + dA)``. The visible share multiplies the exact unoccluded
  kernel at that point, so an unoccluded pair is exact and an occluded one is sampled.
* ``hemicube`` -- Cohen & Greenberg 1985 on the GPU. This module stays GL-free: the caller
  passes the backend, ``FormFactors(..., hemicube=shadelab.raster.hemicube.Hemicube)``.

Rows are computed on demand (:class:`FormFactors`), so progressive refinement can start
shooting before the whole matrix exists, as it did in Cohen et al. 1988.
"""

from __future__ import annotations

import math
from typing import Iterator

import numba
import numpy as np

from shadelab.errors import ShadeLabError
from shadelab.radiosity.patches import PatchSet
from shadelab.radiosity.sampling import (  # noqa: F401  (re-exported)
    GAUSS_ORDER,
    SOURCE_GRID,
    bilinear_samples,
    hemicube_delta_factors,
    receiver_samples,
    source_samples,
)

METHODS = ("hemicube", "raycast", "analytic")
RAYS_PER_POINT = 4  # visibility rays from each receiver point
MAX_RAYS_PER_BATCH = 2_000_000  # bounds memory: rows are processed in blocks


# ---------------------------------------------------------------------- kernels
@numba.njit(cache=True)
def _point_polygon(x, n, poly, eps, buf):
    """Exact unoccluded form factor from a point (unit normal n) to a polygon, clipped to
    the half-space in front of the point (Sutherland-Hodgman on one plane); ``buf`` is
    (8, 3) scratch space."""
    count = 0
    for k in range(4):
        k1 = (k + 1) % 4
        da = ((poly[k, 0] - x[0]) * n[0] + (poly[k, 1] - x[1]) * n[1]
              + (poly[k, 2] - x[2]) * n[2])
        db = ((poly[k1, 0] - x[0]) * n[0] + (poly[k1, 1] - x[1]) * n[1]
              + (poly[k1, 2] - x[2]) * n[2])
        if da >= eps:
            for c in range(3):
                buf[count, c] = poly[k, c] - x[c]
            count += 1
        if (da >= eps) != (db >= eps):
            s = (eps - da) / (db - da)
            for c in range(3):
                buf[count, c] = poly[k, c] + s * (poly[k1, c] - poly[k, c]) - x[c]
            count += 1
    if count < 3:
        return 0.0
    total = 0.0
    for k in range(count):
        k1 = (k + 1) % count
        a0, a1, a2 = buf[k, 0], buf[k, 1], buf[k, 2]
        b0, b1, b2 = buf[k1, 0], buf[k1, 1], buf[k1, 2]
        c0 = a1 * b2 - a2 * b1
        c1 = a2 * b0 - a0 * b2
        c2 = a0 * b1 - a1 * b0
        cn = math.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
        if cn < 1e-300:
            continue
        gamma = math.atan2(cn, a0 * b0 + a1 * b1 + a2 * b2)  # angle between R_k and R_k+1
        total += gamma * (n[0] * c0 + n[1] * c1 + n[2] * c2) / cn
    return abs(total) / (2.0 * math.pi)


@numba.njit(cache=True)
def _faces(pi, ni, pj, nj, eps):
    """Can patch i see the front of patch j at all (some corner in front of each other)?"""
    ahead = False
    for k in range(4):
        if ((pj[k, 0] - pi[0, 0]) * ni[0] + (pj[k, 1] - pi[0, 1]) * ni[1]
                + (pj[k, 2] - pi[0, 2]) * ni[2]) > eps:
            ahead = True
    if not ahead:
        return False
    for k in range(4):
        if ((pi[k, 0] - pj[0, 0]) * nj[0] + (pi[k, 1] - pj[0, 1]) * nj[1]
                + (pi[k, 2] - pj[0, 2]) * nj[2]) > eps:
            return True
    return False


@numba.njit(cache=True)
def _unoccluded(rows, polygons, normals, recv, eps, areas, half):
    """Per-point unoccluded kernels (len(rows), N, K) (zero where j cannot be seen).

    With ``half`` only the pairs whose receiver i is the smaller patch (ties: i < j) are
    computed; reciprocity gives the others.
    """
    n = len(polygons)
    k_count = recv.shape[1]
    out = np.zeros((len(rows), n, k_count))
    buf = np.empty((8, 3))
    for a in range(len(rows)):
        i = rows[a]
        for j in range(n):
            if half and (areas[i] > areas[j] or (areas[i] == areas[j] and i > j)):
                continue
            if j == i or not _faces(polygons[i], normals[i], polygons[j], normals[j], eps):
                continue
            for k in range(k_count):
                # One-sided patches: a point behind j's plane sees only its back
                ahead = ((recv[i, k, 0] - polygons[j, 0, 0]) * normals[j, 0]
                         + (recv[i, k, 1] - polygons[j, 0, 1]) * normals[j, 1]
                         + (recv[i, k, 2] - polygons[j, 0, 2]) * normals[j, 2])
                if ahead > eps:
                    out[a, j, k] = _point_polygon(recv[i, k], normals[i], polygons[j], eps, buf)
    return out


@numba.njit(cache=True)
def _wallace(x0, x1, x2, ni, y0, y1, y2, nj, da):
    """Wallace's disk-approximation weight of the ray x -> y, and the ray's direction."""
    d0, d1, d2 = y0 - x0, y1 - x1, y2 - x2
    r2 = d0 * d0 + d1 * d1 + d2 * d2
    inv = 1.0 / math.sqrt(max(r2, 1e-300))
    ci = max(0.0, (d0 * ni[0] + d1 * ni[1] + d2 * ni[2]) * inv)
    cj = max(0.0, -(d0 * nj[0] + d1 * nj[1] + d2 * nj[2]) * inv)
    return ci * cj * da / (math.pi * r2 + da), d0, d1, d2


@numba.njit(cache=True)
def _build_rays(pairs, recv, src, src_w, normals, areas, rays, eps):
    """Ray origins, directions (to the sample, t in [0, 1]) and Wallace weights per pair.

    Each receiver point aims its ``rays`` rays at source samples it can see at all (in front
    of both patches), spread over them by a rotating stride; a point that sees none of them
    gets weights 0 (its visibility is then taken as 1: the kernel there is a sliver).
    """
    k_count = recv.shape[1]
    s_count = src.shape[1]
    total = len(pairs) * k_count * rays
    origins = np.empty((total, 3), np.float32)
    dirs = np.empty((total, 3), np.float32)
    weights = np.zeros(total)
    front = np.empty(s_count, np.int64)
    r = 0
    for p in range(len(pairs)):
        i, j = pairs[p, 0], pairs[p, 1]
        for k in range(k_count):
            x0 = recv[i, k, 0] + eps * normals[i, 0]
            x1 = recv[i, k, 1] + eps * normals[i, 1]
            x2 = recv[i, k, 2] + eps * normals[i, 2]
            count = 0
            for ell in range(s_count):
                # Wallace's weight is > 0 exactly where the sample is in front of both
                # patches (and has area): two signs, no square root
                d0 = src[j, ell, 0] - x0
                d1 = src[j, ell, 1] - x1
                d2 = src[j, ell, 2] - x2
                if (d0 * normals[i, 0] + d1 * normals[i, 1] + d2 * normals[i, 2] > 0.0
                        and d0 * normals[j, 0] + d1 * normals[j, 1] + d2 * normals[j, 2] < 0.0
                        and src_w[j, ell] > 0.0):
                    front[count] = ell
                    count += 1
            for q in range(rays):
                ell = front[(k * rays + q) % count] if count else (k * rays + q) % s_count
                w, d0, d1, d2 = _wallace(x0, x1, x2, normals[i],
                                         src[j, ell, 0] + eps * normals[j, 0],
                                         src[j, ell, 1] + eps * normals[j, 1],
                                         src[j, ell, 2] + eps * normals[j, 2], normals[j],
                                         areas[j] * src_w[j, ell])
                weights[r] = w if count else 0.0
                origins[r, 0], origins[r, 1], origins[r, 2] = x0, x1, x2
                dirs[r, 0], dirs[r, 1], dirs[r, 2] = d0, d1, d2
                r += 1
    return origins, dirs, weights


@numba.njit(cache=True)
def _section(polygons, i, j, d, lo, hi, inward, pad, c_lo, c_hi, crossings):
    """Where the shaft between patches i and j (the convex hull of their 8 corners) meets a
    planar surface's plane. ``d`` (8,): the corners' signed distances to the plane. The
    hull's section by the plane is the convex hull of the points where corner-to-corner
    segments of opposite sides cross it (and of the corners on it). Returns 0 where that
    section's box, padded by ``pad``, misses the box [lo, hi] (no ray between i and j can
    meet the surface), 2 where i and j lie strictly on opposite sides, every crossing is
    well inside the segments and inside the surface's convex quad ``corners`` by ``pad``
    (every ray between them meets it), else 1. ``inward`` (4, 4): the quad's edges as
    unit inward normals n and offsets o (n . x + o >= 0 inside); ``c_lo``, ``c_hi`` (3,)
    and ``crossings`` (16, 3): scratch space."""
    c_lo[0] = c_lo[1] = c_lo[2] = np.inf
    c_hi[0] = c_hi[1] = c_hi[2] = -np.inf
    whole = ((d[0] > pad and d[1] > pad and d[2] > pad and d[3] > pad
              and d[4] < -pad and d[5] < -pad and d[6] < -pad and d[7] < -pad)
             or (d[0] < -pad and d[1] < -pad and d[2] < -pad and d[3] < -pad
                 and d[4] > pad and d[5] > pad and d[6] > pad and d[7] > pad))
    count = 0
    for q in range(8):
        if d[q] < 0.0:
            continue
        pq = i if q < 4 else j
        kq = q % 4
        if d[q] == 0.0:
            for c in range(3):
                c_lo[c] = min(c_lo[c], polygons[pq, kq, c])
                c_hi[c] = max(c_hi[c], polygons[pq, kq, c])
            continue
        for r in range(8):
            if d[r] >= 0.0:
                continue
            pr = i if r < 4 else j
            kr = r % 4
            t = d[q] / (d[q] - d[r])
            if whole:  # t from i's side: rays start on i and stop 1e-4 short of j
                ti = t if q < 4 else 1.0 - t
                if ti < 1e-3 or ti > 1.0 - 1e-3:
                    whole = False
            x0 = polygons[pq, kq, 0] + t * (polygons[pr, kr, 0] - polygons[pq, kq, 0])
            x1 = polygons[pq, kq, 1] + t * (polygons[pr, kr, 1] - polygons[pq, kq, 1])
            x2 = polygons[pq, kq, 2] + t * (polygons[pr, kr, 2] - polygons[pq, kq, 2])
            c_lo[0], c_hi[0] = min(c_lo[0], x0), max(c_hi[0], x0)
            c_lo[1], c_hi[1] = min(c_lo[1], x1), max(c_hi[1], x1)
            c_lo[2], c_hi[2] = min(c_lo[2], x2), max(c_hi[2], x2)
            if count < 16:
                crossings[count, 0], crossings[count, 1], crossings[count, 2] = x0, x1, x2
            count += 1
    for c in range(3):
        if c_hi[c] + pad < lo[c] or c_lo[c] - pad > hi[c]:
            return 0
    if not whole or count == 0 or count > 16:
        return 1
    for k in range(4):
        for m in range(count):
            if (inward[k, 0] * crossings[m, 0] + inward[k, 1] * crossings[m, 1]
                    + inward[k, 2] * crossings[m, 2] + inward[k, 3]) < pad:
                return 1
    return 2


@numba.njit(cache=True)
def _sides(polygons, planes, planar, eps):
    """(N, S) int8 per patch and planar surface: bit 1 if a corner lies in front of its
    plane (beyond eps), bit 2 if one lies behind."""
    out = np.zeros((len(polygons), len(planes)), np.int8)
    for i in range(len(polygons)):
        for s in range(len(planes)):
            if not planar[s]:
                continue
            for k in range(4):
                d = (planes[s, 0] * polygons[i, k, 0] + planes[s, 1] * polygons[i, k, 1]
                     + planes[s, 2] * polygons[i, k, 2] + planes[s, 3])
                if d > eps:
                    out[i, s] |= 1
                elif d < -eps:
                    out[i, s] |= 2
    return out


@numba.njit(cache=True)
def _blockable(pairs, polygons, surface_of, planes, planar, lo, hi, inward, sides, eps):
    """Shaft culling (after Haines & Wallace 1991): can any surface block patch i from j?

    A surface can only if the box around both patches meets its box and, when it is
    planar, the two patches are not both in front of (or both behind) its plane and the
    shaft between them crosses that plane inside the surface's box (:func:`_crosses_box`).
    Culled pairs are those no ray between them can hit, so the matrix is the same with
    fewer rays (Cornell, 1029 patches: 4.4 M rays -> 3.4 M). Returns per pair 0 (nothing
    can block: no rays), 1 (cast the rays) or 2 (one planar surface blocks every ray, see
    :func:`_section`: no rays, visibility 0). Patch sets without surfaces (one surface 0
    for all) keep every pair.
    """
    out = np.zeros(len(pairs), np.int8)
    count = len(planes)
    pad = 100.0 * eps  # rays start and end eps off the patches
    blo = np.empty(3)
    bhi = np.empty(3)
    d = np.empty(8)
    c_lo = np.empty(3)
    c_hi = np.empty(3)
    crossings = np.empty((16, 3))
    for p in range(len(pairs)):
        i, j = pairs[p, 0], pairs[p, 1]
        for c in range(3):
            low, high = polygons[i, 0, c], polygons[i, 0, c]
            for q in (i, j):
                for k in range(4):
                    low = min(low, polygons[q, k, c])
                    high = max(high, polygons[q, k, c])
            blo[c], bhi[c] = low, high
        for s in range(count):
            if count > 1 and (s == surface_of[i] or s == surface_of[j]) and planar[s]:
                continue  # a flat surface cannot hide its own patches from each other
            if (bhi[0] < lo[s, 0] or blo[0] > hi[s, 0] or bhi[1] < lo[s, 1]
                    or blo[1] > hi[s, 1] or bhi[2] < lo[s, 2] or blo[2] > hi[s, 2]):
                continue
            if planar[s] and count > 1:
                if (sides[i, s] | sides[j, s]) != 3:
                    continue  # both patches in front of its plane, or both behind
                for q in range(8):
                    patch = i if q < 4 else j
                    k = q % 4
                    d[q] = (planes[s, 0] * polygons[patch, k, 0]
                            + planes[s, 1] * polygons[patch, k, 1]
                            + planes[s, 2] * polygons[patch, k, 2] + planes[s, 3])
                code = _section(polygons, i, j, d, lo[s], hi[s], inward[s], pad, c_lo, c_hi,
                                crossings)
                if code == 0:
                    continue
                if code == 2:
                    out[p] = 2
                    break
            out[p] = 1
            if not planar[s]:
                break  # a curved surface: the rays decide
    return out


@numba.njit(cache=True)
def _seen_pairs(kernel, rows):
    """(pairs (P, 2) of (patch i, patch j), a (P,) the block row of i) where some receiver
    point of i sees j (kernel > 0)."""
    count = 0
    for a in range(kernel.shape[0]):
        for j in range(kernel.shape[1]):
            for k in range(kernel.shape[2]):
                if kernel[a, j, k] > 0.0:
                    count += 1
                    break
    pairs = np.empty((count, 2), np.int64)
    block = np.empty(count, np.int64)
    p = 0
    for a in range(kernel.shape[0]):
        for j in range(kernel.shape[1]):
            for k in range(kernel.shape[2]):
                if kernel[a, j, k] > 0.0:
                    pairs[p, 0], pairs[p, 1], block[p] = rows[a], j, a
                    p += 1
                    break
    return pairs, block


@numba.njit(cache=True)
def _hide(kernel, a, pairs, recv, src, src_w, normals, eps):
    """Pairs with a surface across their whole shaft: visibility 0 at every receiver point
    that sees a source sample in front of both patches (as its rays would all be blocked;
    a point that sees none keeps its kernel, as in :func:`_apply_visibility`)."""
    k_count = recv.shape[1]
    s_count = src.shape[1]
    for p in range(len(pairs)):
        i, j = pairs[p, 0], pairs[p, 1]
        for k in range(k_count):
            x0 = recv[i, k, 0] + eps * normals[i, 0]
            x1 = recv[i, k, 1] + eps * normals[i, 1]
            x2 = recv[i, k, 2] + eps * normals[i, 2]
            for ell in range(s_count):
                d0 = src[j, ell, 0] - x0
                d1 = src[j, ell, 1] - x1
                d2 = src[j, ell, 2] - x2
                if (d0 * normals[i, 0] + d1 * normals[i, 1] + d2 * normals[i, 2] > 0.0
                        and d0 * normals[j, 0] + d1 * normals[j, 1] + d2 * normals[j, 2] < 0.0
                        and src_w[j, ell] > 0.0):
                    kernel[a[p], j, k] = 0.0
                    break


@numba.njit(cache=True)
def _apply_visibility(kernel, a, j, hit, weights, rays):
    """kernel[a, j, k] *= seen / total of the Wallace weights of point k's rays (a point
    whose rays all have weight 0 keeps its kernel: it is a sliver)."""
    k_count = kernel.shape[2]
    r = 0
    for p in range(len(a)):
        for k in range(k_count):
            seen = total = 0.0
            for _ in range(rays):
                total += weights[r]
                if not hit[r]:
                    seen += weights[r]
                r += 1
            if total > 0.0:
                kernel[a[p], j[p], k] *= seen / max(total, 1e-300)


@numba.njit(cache=True)
def _integrate(kernel, weights):
    """(rows, N): sum_k kernel[a, j, k] * weights[a, k] (the receiver quadrature)."""
    out = np.zeros((kernel.shape[0], kernel.shape[1]))
    for a in range(kernel.shape[0]):
        for j in range(kernel.shape[1]):
            total = 0.0
            for k in range(kernel.shape[2]):
                total += kernel[a, j, k] * weights[a, k]
            out[a, j] = total
    return out


# ---------------------------------------------------------------------- the engine
class FormFactors:
    """Rows of the form-factor matrix of a patch set, computed on demand and cached.

    Parameters
    ----------
    patches : the patch set
    method : "raycast" | "analytic" | "hemicube"
    resolution : hemicube face resolution in pixels (top face resolution x resolution)
    rays : visibility rays per receiver point (raycast)
    hemicube_samples : hemicubes per patch, 1 (centre) or 9 (3x3 Gauss points)
    order : receiver quadrature, order x order Gauss-Legendre points (raycast, analytic)
    hemicube : the GPU backend for ``method="hemicube"``: a factory
        ``hemicube(patches, resolution, samples)`` of an object with ``rows(indices)`` and
        ``release()``, e.g. :class:`shadelab.raster.hemicube.Hemicube` (required for hemicube)
    """

    def __init__(self, patches: PatchSet, method: str = "raycast", resolution: int = 128,
                 rays: int = RAYS_PER_POINT, hemicube_samples: int = 1,
                 order: int = GAUSS_ORDER, hemicube=None):
        if method not in METHODS:
            raise ValueError(f"form factor method {method!r}: expected one of {METHODS}")
        check_backend(method, hemicube)
        self.patches = patches
        self.method = method
        self.resolution = int(resolution)
        self.rays = int(rays)
        self.hemicube_samples = int(hemicube_samples)
        self.n = len(patches)
        span = np.ptp(patches.polygons.reshape(-1, 3), axis=0)
        self.eps = 1e-6 * float(max(np.linalg.norm(span), 1e-12))
        self._rows: dict[int, np.ndarray] = {}
        self._recv, self._recv_w = receiver_samples(patches.polygons, order)
        self._src, self._src_w = None, None
        self._embree = None
        self._hemicube_factory = hemicube
        self._hemicube = None
        self._occluder_data = None

    # ------------------------------------------------------------ public
    def row(self, i: int) -> np.ndarray:
        """F_i. as (N,) float64."""
        i = int(i)
        if i not in self._rows:
            self.compute_rows(np.array([i]))
        return self._rows[i]

    def compute_rows(self, rows: np.ndarray) -> np.ndarray:
        """Compute (and cache) the given rows; returns (len(rows), N)."""
        rows = np.asarray(rows, np.int64)
        todo = np.array([r for r in rows if int(r) not in self._rows], np.int64)
        if len(todo):
            block = max(1, MAX_RAYS_PER_BATCH // max(1, self.n * order_sq(self) * self.rays))
            for start in range(0, len(todo), block):
                part = todo[start:start + block]
                for r, values in zip(part, self._compute(part), strict=True):
                    self._rows[int(r)] = values
        if not len(rows):
            return np.zeros((0, self.n))
        return np.stack([self._rows[int(r)] for r in rows])

    def matrix(self) -> np.ndarray:
        """The full (N, N) matrix F, F[i, j] = F_ij.

        Ray-cast and analytic factors are computed once per pair, from the smaller patch
        (quadrature over it, the exact kernel over the larger one, as Baum et al. 1989
        advise), and the other direction follows by reciprocity A_i F_ij = A_j F_ji: half the
        work, and a matrix reciprocal to rounding, so shooting and gathering solve one system.
        """
        for _ in self.iter_matrix():
            pass
        return self.compute_rows(np.arange(self.n))

    def iter_matrix(self, blocks: int = 20) -> Iterator[float]:
        """Compute the full matrix in about ``blocks`` steps, yielding the share done."""
        rows_per = max(1, self.n // blocks)
        if self.method == "hemicube":
            for start in range(0, self.n, rows_per):
                self.compute_rows(np.arange(start, min(start + rows_per, self.n)))
                yield min(start + rows_per, self.n) / self.n
            return
        if len(self._rows) == self.n:
            return
        half = np.zeros((self.n, self.n))
        limit = max(1, MAX_RAYS_PER_BATCH // max(1, self.n * order_sq(self) * self.rays // 2))
        for start in range(0, self.n, min(rows_per, limit)):
            rows = np.arange(start, min(start + min(rows_per, limit), self.n))
            half[rows] = self._compute(rows, half=True)
            yield rows[-1] / self.n
        areas = self.patches.areas
        F = half + (half * areas[:, None]).T / areas[:, None]
        for i in range(self.n):
            self._rows[i] = F[i]
        yield 1.0

    # ------------------------------------------------------------ methods
    def _compute(self, rows: np.ndarray, half: bool = False) -> np.ndarray:
        if self.method == "hemicube":
            return self._hemicube_rows(rows)
        p = self.patches
        kernel = _unoccluded(rows, p.polygons, p.normals, self._recv, self.eps, p.areas, half)
        if self.method == "raycast":
            self._visibility(rows, kernel)
        return _integrate(kernel, self._recv_w[rows])

    def _visibility(self, rows: np.ndarray, kernel: np.ndarray) -> None:
        """Multiply the per-point kernels (len(rows), N, K) by their Wallace-weighted visible
        share, in place (pairs no surface can come between keep 1)."""
        p = self.patches
        if self._src is None:
            self._src, self._src_w = source_samples(p.polygons)
        pairs, a = _seen_pairs(kernel, rows)
        if len(a) == 0:
            return
        # Shaft culling: rays only where some surface could stand between the two patches,
        # and none where one surface stands across the whole shaft
        code = _blockable(pairs, p.polygons, p.surface, *self._occluders())
        hidden = code == 2
        if hidden.any():
            _hide(kernel, a[hidden], pairs[hidden], self._recv, self._src, self._src_w,
                  p.normals, self.eps)
        a, pairs = a[code == 1], pairs[code == 1]
        if len(a) == 0:
            return
        origins, dirs, weights = _build_rays(pairs, self._recv, self._src, self._src_w,
                                             p.normals, p.areas, self.rays, self.eps)
        hit = self._occluded(origins, dirs)
        _apply_visibility(kernel, a, pairs[:, 1], hit, weights, self.rays)

    def _occluders(self):
        """Per surface: plane (n, d) if planar, and its bounding box (padded by eps)."""
        if self._occluder_data is None:
            p = self.patches
            count = max(int(p.surface.max(initial=-1)) + 1, 0)
            planes = np.zeros((count, 4))
            planar = np.zeros(count, np.bool_)
            lo = np.full((count, 3), np.inf)
            hi = np.full((count, 3), -np.inf)
            inward = np.zeros((count, 4, 4))  # quad edges: unit inward normal, offset
            for index in range(count):
                corners = p.polygons[p.surface == index].reshape(-1, 3)
                if len(corners) == 0:
                    continue
                lo[index] = corners.min(axis=0) - self.eps
                hi[index] = corners.max(axis=0) + self.eps
                surface = p.surfaces[index] if index < len(p.surfaces) else None
                if surface is not None and surface.kind == "quad":
                    n = p.normals[p.surface == index][0]
                    planes[index] = (*n, -float(n @ corners[0]))
                    planar[index] = True
                    for k in range(4):
                        edge = surface.corners[(k + 1) % 4] - surface.corners[k]
                        w = np.cross(n, edge)
                        w /= max(float(np.linalg.norm(w)), 1e-300)
                        inward[index, k] = (*w, -float(w @ surface.corners[k]))
            sides = _sides(p.polygons, planes, planar, self.eps)
            self._occluder_data = (planes, planar, lo, hi, inward, sides, self.eps)
        return self._occluder_data

    def _occluded(self, origins: np.ndarray, dirs: np.ndarray) -> np.ndarray:
        if self._embree is None:
            self._embree = patch_scene(self.patches)
        dists = np.full(len(origins), 1.0 - 1e-4, np.float32)
        return self._embree.run(origins, dirs, dists=dists, query="OCCLUDED") != -1

    def _hemicube_rows(self, rows: np.ndarray) -> np.ndarray:
        if self._hemicube is None:
            self._hemicube = self._hemicube_factory(self.patches, self.resolution,
                                                    self.hemicube_samples)
        return self._hemicube.rows(rows)


def check_backend(method: str, hemicube) -> None:
    """Refuse ``method="hemicube"`` without a GPU backend (this layer imports no GL)."""
    if method == "hemicube" and hemicube is None:
        raise ShadeLabError("hemicube form factors need a GPU backend: pass "
                            "hemicube=shadelab.raster.hemicube.Hemicube (or use "
                            "form_factors='raycast')")


def order_sq(ff: FormFactors) -> int:
    """Receiver points per patch."""
    return int(ff._recv.shape[1])  # noqa: SLF001


def patch_scene(patches: PatchSet):
    """An embreex scene of every patch (two triangles each; both sides occlude)."""
    import embreex.mesh_construction as mc
    import embreex.rtcore_scene as rs

    tri = np.concatenate([patches.polygons[:, [0, 1, 2]], patches.polygons[:, [0, 2, 3]]])
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    scene = rs.EmbreeScene()
    mc.TriangleMesh(scene, np.ascontiguousarray(tri[area > 0], np.float32))
    return scene


def form_factor_matrix(patches: PatchSet, method: str = "raycast", **options) -> np.ndarray:
    """The (N, N) form-factor matrix by the named method."""
    return FormFactors(patches, method, **options).matrix()


def heatmap_data(F: np.ndarray) -> dict:
    """Data for the viewer's heat map: the matrix, its row sums (1 in a closed scene), range."""
    return {"matrix": F, "row_sums": F.sum(axis=1), "min": float(F.min(initial=0.0)),
            "max": float(F.max(initial=0.0))}


def point_polygon(x, n, polygon) -> float:
    """Exact unoccluded form factor from point ``x`` (unit normal ``n``) to a polygon (k, 3)."""
    poly = np.asarray(polygon, float)
    if len(poly) == 3:
        poly = poly[[0, 1, 2, 2]]
    return float(_point_polygon(np.asarray(x, float), np.asarray(n, float), poly, 0.0,
                                np.empty((8, 3))))
