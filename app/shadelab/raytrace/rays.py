"""numba kernels that make rays and add what they bring back: camera rays, the spawning of
Whitted's secondary (reflected and refracted) rays, and the per-pixel accumulation."""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from shadelab.raytrace.scatter import _fr_dielectric, _ior_pair, _reflect, _refract


@nb.njit(cache=True, inline="always")
def _store_ray(out_o, out_d, out_w, out_p, count, position, geo, i, side, eps, d, w, pixel):
    """Row ``count`` of the next generation: origin off the surface on ``side``, d, w, pixel."""
    out_d[count, 0], out_d[count, 1], out_d[count, 2] = d
    for c in range(3):
        out_o[count, c] = position[i, c] + side * eps * geo[i, c]
    out_w[count, 0], out_w[count, 1], out_w[count, 2] = w
    out_p[count] = pixel


@nb.njit(cache=True)
def spawn_secondary(position, normal, geo, entering, dirs, mat, weight, pixel, kr, kt, ior,
                    tint, fresnel, min_weight, eps):
    """The next generation: reflected and refracted rays whose weight reaches ``min_weight``.

    Mirrors :meth:`TraceContext.secondary` + :func:`reflect_refract` (constant kr/kt with
    total internal reflection sending kt to reflection, or Fresnel's split of kt).
    Returns origins, directions, RGB weights and pixel indices of the kept rays.
    """
    n = len(dirs)
    out_o = np.empty((2 * n, 3))
    out_d = np.empty((2 * n, 3))
    out_w = np.empty((2 * n, 3))
    out_p = np.empty(2 * n, np.int64)
    count = spawn_secondary_into(out_o, out_d, out_w, out_p, position, normal, geo, entering,
                                 dirs, mat, weight, pixel, kr, kt, ior, tint, fresnel,
                                 min_weight, eps)
    return out_o[:count], out_d[:count], out_w[:count], out_p[:count]


@nb.njit(cache=True)
def spawn_secondary_into(out_o, out_d, out_w, out_p, position, normal, geo, entering, dirs, mat,
                         weight, pixel, kr, kt, ior, tint, fresnel, min_weight, eps):
    """:func:`spawn_secondary` into the arrays passed (2 N rows each); returns the count."""
    n = len(dirs)
    count = 0
    threshold = max(min_weight, 1e-12)
    for i in range(n):
        m = mat[i]
        if kr[m] == 0.0 and kt[m] == 0.0:
            continue  # both weights are 0: nothing to spawn
        dx, dy, dz = dirs[i, 0], dirs[i, 1], dirs[i, 2]
        nx, ny, nz = normal[i, 0], normal[i, 1], normal[i, 2]
        cos_i = min(max(-(dx * nx + dy * ny + dz * nz), 0.0), 1.0)
        n1, n2 = _ior_pair(entering[i], ior[m])
        f, cos_t, tir = _fr_dielectric(cos_i, n1, n2)
        if fresnel:
            refl_s = kr[m] + kt[m] * f
            refr_s = kt[m] * (1.0 - f)
        else:
            refl_s = kr[m] + (kt[m] if tir else 0.0)
            refr_s = 0.0 if tir else kt[m]
        # Reflected ray
        wr = (weight[i, 0] * refl_s, weight[i, 1] * refl_s, weight[i, 2] * refl_s)
        if max(wr[0], max(wr[1], wr[2])) >= threshold:
            _store_ray(out_o, out_d, out_w, out_p, count, position, geo, i, 1.0, eps,
                       _reflect(dx, dy, dz, nx, ny, nz, cos_i), wr, pixel[i])
            count += 1
        # Refracted ray
        wt = (weight[i, 0] * refr_s * tint[m, 0], weight[i, 1] * refr_s * tint[m, 1],
              weight[i, 2] * refr_s * tint[m, 2])
        if max(wt[0], max(wt[1], wt[2])) >= threshold:
            _store_ray(out_o, out_d, out_w, out_p, count, position, geo, i, -1.0, eps,
                       _refract(dx, dy, dz, nx, ny, nz, n1 / n2, cos_i, cos_t), wt, pixel[i])
            count += 1
    return count


@nb.njit(cache=True)
def add_rows(out, pixel, value, mask):
    """out[pixel[i]] += value[i] where mask[i] (serial: pixels repeat)."""
    for i in range(len(pixel)):
        if mask[i]:
            for c in range(3):
                out[pixel[i], c] += value[i, c]


@nb.njit(cache=True)
def camera_rays(eye, forward, right, up, tan_half, width, height, r0, r1, jitter):
    """Rows r0..r1 of :func:`shadelab.scene.camera.primary_rays`, flattened (same formulas);
    ``jitter`` (r1 - r0, width, 2), or shape (0, 0, 2) for pixel centres."""
    n = (r1 - r0) * width
    origins = np.empty((n, 3))
    dirs = np.empty((n, 3))
    camera_rays_into(origins, dirs, eye, forward, right, up, tan_half, width, height, r0, r1,
                     jitter)
    return origins, dirs


@nb.njit(cache=True)
def camera_rays_into(origins, dirs, eye, forward, right, up, tan_half, width, height, r0, r1,
                     jitter):
    """:func:`camera_rays` into the arrays passed ((r1 - r0) width rows each). Serial: a
    parallel kernel called from a cached njit function (:func:`camera_rays`) crashes when it
    is loaded from numba's cache before any parallel kernel has started the thread pool."""
    aspect = width / height
    centre = jitter.shape[0] == 0
    for j in range(r0, r1):
        for i in range(width):
            k = (j - r0) * width + i
            jx = 0.5 if centre else jitter[j - r0, i, 0]
            jy = 0.5 if centre else jitter[j - r0, i, 1]
            x = (2.0 * ((i + jx) / width) - 1.0) * tan_half * aspect
            y = (1.0 - 2.0 * ((j + jy) / height)) * tan_half
            dx = forward[0] + x * right[0] + y * up[0]
            dy = forward[1] + x * right[1] + y * up[1]
            dz = forward[2] + x * right[2] + y * up[2]
            length = math.sqrt(dx * dx + dy * dy + dz * dz)
            dirs[k, 0], dirs[k, 1], dirs[k, 2] = dx / length, dy / length, dz / length
            origins[k, 0], origins[k, 1], origins[k, 2] = eye[0], eye[1], eye[2]


@nb.njit(cache=True)
def add_weighted(out, pixel, weight, value):
    """out[pixel[i]] += weight[i] * value[i] (RGB)."""
    for i in range(len(pixel)):
        for c in range(3):
            out[pixel[i], c] += weight[i, c] * value[i, c]


@nb.njit(cache=True)
def add_background(out, pixel, weight, hit, background):
    """out[pixel[i]] += weight[i] * background where the ray missed."""
    for i in range(len(pixel)):
        if not hit[i]:
            for c in range(3):
                out[pixel[i], c] += weight[i, c] * background[c]


@nb.njit(cache=True)
def add_misses(out, pixel, weight, tri, background):
    """out[pixel[i]] += weight[i] * background where the ray missed (``tri`` < 0)."""
    for i in range(len(pixel)):
        if tri[i] < 0:
            for c in range(3):
                out[pixel[i], c] += weight[i, c] * background[c]

