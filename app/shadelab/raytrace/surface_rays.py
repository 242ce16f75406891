"""numba kernels of the Whitted tracer's hits and shadow rays: the surface frame at hits,
shadow-ray set-up to every light, the S_i matrices, and the kt-filtered shadow rays' steps
through transparent casters (:class:`shadelab.raytrace.surface.TraceContext`)."""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from shadelab.shading.kernels import _to_light


@nb.njit(cache=True, parallel=True)
def surface_frame(origins, dirs, t, tri, u, v, corner_normals, face_normals, object_index):
    """Hit positions, unit shading and geometric normals facing the ray, entering flags."""
    n = len(t)
    position = np.empty((n, 3))
    normal = np.empty((n, 3))
    geo = np.empty((n, 3))
    entering = np.empty(n, np.bool_)
    obj = np.empty(n, np.int64)
    for i in nb.prange(n):
        f = tri[i]
        w0 = 1.0 - u[i] - v[i]
        side = 0.0
        for c in range(3):
            position[i, c] = origins[i, c] + t[i] * dirs[i, c]
            normal[i, c] = (w0 * corner_normals[f, 0, c] + u[i] * corner_normals[f, 1, c]
                            + v[i] * corner_normals[f, 2, c])
            side += face_normals[f, c] * dirs[i, c]
        length = math.sqrt(normal[i, 0] ** 2 + normal[i, 1] ** 2 + normal[i, 2] ** 2)
        sign = 1.0 if side < 0.0 else -1.0
        entering[i] = side < 0.0
        for c in range(3):
            normal[i, c] = sign * normal[i, c] / max(length, 1e-300)
            geo[i, c] = sign * face_normals[f, c]
        obj[i] = object_index[f]
    return position, normal, geo, entering, obj


@nb.njit(cache=True, parallel=True)
def shadow_rays(position, geo, lights, k, eps, t_inf):
    """Origins, directions and tmax of shadow rays to light k, and which points face it."""
    n = len(position)
    origins = np.empty((n, 3))
    dirs = np.empty((n, 3))
    tmax = np.empty(n)
    facing = np.empty(n, np.bool_)
    for i in nb.prange(n):
        lx, ly, lz, dist = _to_light(lights, k, position[i, 0], position[i, 1], position[i, 2])
        facing[i] = geo[i, 0] * lx + geo[i, 1] * ly + geo[i, 2] * lz > 0.0
        dirs[i, 0], dirs[i, 1], dirs[i, 2] = lx, ly, lz
        for c in range(3):
            origins[i, c] = position[i, c] + eps * geo[i, c]
        tmax[i] = dist - eps if math.isfinite(dist) else t_inf
    return origins, dirs, tmax, facing


@nb.njit(cache=True, parallel=True)
def hit_surfaces(origins, dirs, weight, pixel, t, tri, u, v, hit, corner_normals, face_normals,
                 object_index, object_material, position, normal, geo, entering, mat, d_hit,
                 w_hit, p_hit):
    """:func:`surface_frame` at the rays ``hit`` of a batch, gathered in the same pass.

    ``t``, ``tri``, ``u``, ``v`` as the accelerator gives them (Embree's float32 and int32, or
    float64 and int64), widened to float64 exactly as ``Hits`` does. Returns position,
    shading and geometric normals, entering, material index, and the hit rays' directions,
    weights and pixels, written into the arrays passed (each with len(hit) rows; the caller
    allocates them, so they can be reused from one generation to the next).
    """
    n = len(hit)
    for j in nb.prange(n):
        i = hit[j]
        f = np.int64(tri[i])
        ti, ui, vi = np.float64(t[i]), np.float64(u[i]), np.float64(v[i])
        w0 = 1.0 - ui - vi
        side = 0.0
        for c in range(3):
            position[j, c] = origins[i, c] + ti * dirs[i, c]
            normal[j, c] = (w0 * corner_normals[f, 0, c] + ui * corner_normals[f, 1, c]
                            + vi * corner_normals[f, 2, c])
            side += face_normals[f, c] * dirs[i, c]
            d_hit[j, c] = dirs[i, c]
            w_hit[j, c] = weight[i, c]
        length = math.sqrt(normal[j, 0] ** 2 + normal[j, 1] ** 2 + normal[j, 2] ** 2)
        sign = 1.0 if side < 0.0 else -1.0
        entering[j] = side < 0.0
        for c in range(3):
            normal[j, c] = sign * normal[j, c] / max(length, 1e-300)
            geo[j, c] = sign * face_normals[f, c]
        mat[j] = object_material[object_index[f]]
        p_hit[j] = pixel[i]


@nb.njit(cache=True)
def shadow_batch(position, geo, lights, eps, t_inf, o32, d32, t32, light, point):
    """:func:`shadow_rays` to every light at once, only where the point faces the light:
    float32 origins, directions and tmax (as Embree takes them) with the light and point of
    each ray, written into the arrays passed (N L rows each); returns the count."""
    n = len(position)
    n_lights = len(lights)
    count = 0
    for i in range(n):
        for k in range(n_lights):
            lx, ly, lz, dist = _to_light(lights, k, position[i, 0], position[i, 1],
                                         position[i, 2])
            if not geo[i, 0] * lx + geo[i, 1] * ly + geo[i, 2] * lz > 0.0:
                continue
            d32[count, 0], d32[count, 1], d32[count, 2] = lx, ly, lz
            for c in range(3):
                o32[count, c] = position[i, c] + eps * geo[i, c]
            t32[count] = min(dist - eps, t_inf) if math.isfinite(dist) else t_inf
            light[count] = k
            point[count] = i
            count += 1
    return count


@nb.njit(cache=True)
def shadow_matrix(n_lights, n, light, point, blocked):
    """S_i (L, N): 1 where the point faces light i and nothing blocks it, else 0."""
    s = np.zeros((n_lights, n))
    for j in range(len(light)):
        if not blocked[j]:
            s[light[j], point[j]] = 1.0
    return s


@nb.njit(cache=True)
def shadow_matrix3(s, light, point, blocked, trans):
    """S_i (L, N, 3) of kt-filtered shadows, into ``s``: 1 where the point faces light i and
    nothing blocks it, the transmittance row of each blocked ray (``trans`` holds one row per
    blocked ray, in ray order) where something does, else 0."""
    s[:] = 0.0
    b = 0
    for j in range(len(light)):
        k, i = light[j], point[j]
        if blocked[j]:
            for c in range(3):
                s[k, i, c] = trans[b, c]
            b += 1
        else:
            for c in range(3):
                s[k, i, c] = 1.0


@nb.njit(cache=True)
def gather_rays(active, o, d, left, o_out, d_out, left_out):
    """Rows ``active`` of the shadow rays (origins, directions, distance left) into the
    arrays passed, for the next closest-hit query."""
    for j in range(len(active)):
        r = active[j]
        for c in range(3):
            o_out[j, c] = o[r, c]
            d_out[j, c] = d[r, c]
        left_out[j] = left[r]


@nb.njit(cache=True)
def transmit_step(active, t, tri, trans, o, d, left, casts, object_index, object_material,
                  filt, eps, next_active):
    """One crossing of :meth:`TraceContext.shadow_transmittance` for the rays ``active`` with
    their closest hits (``t``, ``tri`` as the accelerator gives them): a hit closer than the
    distance left multiplies the ray's transmittance by its material's kt Ot (1 for objects
    that cast no shadow) and restarts the ray eps past it; the rays still carrying light with
    distance left go to ``next_active``; returns their count."""
    count = 0
    for j in range(len(active)):
        r = active[j]
        f = np.int64(tri[j])
        if f < 0:
            continue
        tj = np.float64(t[j])
        if not tj < left[r]:
            continue
        if casts[f]:
            m = object_material[object_index[f]]
            for c in range(3):
                trans[r, c] *= filt[m, c]
        step = tj + eps
        for c in range(3):
            o[r, c] += step * d[r, c]
        left[r] -= step
        if max(trans[r, 0], max(trans[r, 1], trans[r, 2])) > 0.0 and left[r] > 0.0:
            next_active[count] = r
            count += 1
    return count

