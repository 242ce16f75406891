"""The path tracer's whole paths in one parallel numba loop (issue 19.3).

The wavefront (:meth:`shadelab.raytrace.pathtrace.PathTracer.radiance`) goes back to Python
at every bounce: a batch for Embree, the hits' surfaces, the Sobol' draws, the vertex kernel,
a batch of shadow rays, the survivors gathered. Here one call traces a tile: ``prange`` over
its pixels, each pixel's sample passes in turn, each path from the camera to its end, Embree
called ray by ray from numba (:mod:`shadelab.raytrace.embree_direct`). The estimator is the
wavefront's line for line: the same camera jitter and Sobol' draws
(:func:`shadelab.raytrace.sampler.vertex_draws`), the same vertex
(:func:`shadelab.raytrace.vertex.next_event_ray`, :func:`~shadelab.raytrace.vertex.continue_path`),
the same float32 rays into the same Embree build, the contributions summed in the same
order, so the image is the wavefront's bit for bit (tests/raytrace/test_fused.py).

Used for the Sobol' sampler on scenes without the lecture's delta lights and textures (the
Cornell boxes); the rest stays on the wavefront (``pathtrace.FUSED = False`` or
``SHADELAB_EMBREE_DIRECT=0`` keeps every render there).

Speed: each pixel is one call of :func:`trace_pixel`, into which numba inlines the vertex and
the draws (``inline="always"``: without it every call passed the material and emitter arrays
and counted their references, and a sample cost 2.5 us of CPU instead of 1.6). A call of 31 or
more arguments reaches numba as ``*args``, which it cannot inline: keep the inlined helpers'
calls shorter. On cornell (64 x 64, 64 spp) a sample costs about 0.9 us in Embree (six rays,
robust mode, as embreex builds) and 0.7 us here.
"""

from __future__ import annotations

import math

import numba as nb

from shadelab.constants import T_INF
from shadelab.raytrace.embree_direct import intersect1, occluded1, ray_buffer
from shadelab.raytrace.sampler import _pixel_seed, sample_2d, vertex_draws
from shadelab.raytrace.vertex import _emission_weight, continue_path, next_event_ray

NO_HIT_TMAX = 1e37   # embreex's tfar for a batch traced without distances
CHUNK = 8            # pixels per work item of the parallel loop
DYNAMIC_CHUNKS = 4   # work items a thread takes at a time (numba.parallel_chunksize)


@nb.njit(cache=True, parallel=True)
def trace_tile(out, counts, fns, eye, forward, right, up, tan_half, width, height, r0, r1,
               first, passes, seed, surfaces, lobes, emitters, frame, eps, background,
               rr_start, max_bounces, blinn):
    """Rows r0..r1 of sample passes first .. first + passes - 1: ``out`` ((r1 - r0) width, 3)
    receives each pixel's radiance summed over the passes; ``counts`` (same rows, 2): rays
    cast, and whether the first pass's camera ray hit. ``fns`` = (rtcIntersect1,
    rtcOccluded1, scene) addresses; ``frame`` = (corner normals, face normals, object
    index, object material) of the triangles; the rest as
    :func:`shadelab.raytrace.vertex.path_vertex`."""
    n = (r1 - r0) * width
    chunks = (n + CHUNK - 1) // CHUNK
    for chunk in nb.prange(chunks):
        words, ints, addr = ray_buffer()
        for k in range(chunk * CHUNK, min(n, (chunk + 1) * CHUNK)):
            trace_pixel(out, counts, k, words, ints, addr, fns, eye, forward, right, up,
                        tan_half, width, height, r0, first, passes, seed, surfaces, lobes,
                        emitters, frame, eps, background, rr_start, max_bounces, blinn)


@nb.njit(cache=True, error_model="numpy")
def trace_pixel(out, counts, k, words, ints, addr, fns, eye, forward, right, up, tan_half,
                width, height, r0, first, passes, seed, surfaces, lobes, emitters, frame, eps,
                background, rr_start, max_bounces, blinn):
    """Pixel k of the tile (:func:`trace_tile`), in the thread's ray buffer ``words``."""
    fn_hit, fn_occ, scene = fns
    corner_normals, face_normals, object_index, object_material = frame
    rho, kr, kt, ior, emission = surfaces
    p_glossy = lobes[2]
    em_cdf = emitters[0]
    em_area = emitters[6]
    n_em = len(em_cdf)
    aspect = width / height
    j = r0 + k // width
    i = k % width
    ps = _pixel_seed(seed, j * width + i)
    rays = 0
    total_r = total_g = total_b = 0.0
    for s in range(first, first + passes):
        # The camera ray through the jittered pixel (rays.camera_rays_into)
        jx, jy = sample_2d(ps, 0, s)
        x = (2.0 * ((i + jx) / width) - 1.0) * tan_half * aspect
        y = (1.0 - 2.0 * ((j + jy) / height)) * tan_half
        dx = forward[0] + x * right[0] + y * up[0]
        dy = forward[1] + x * right[1] + y * up[1]
        dz = forward[2] + x * right[2] + y * up[2]
        length = math.sqrt(dx * dx + dy * dy + dz * dz)
        dx, dy, dz = dx / length, dy / length, dz / length
        ox, oy, oz = eye[0], eye[1], eye[2]
        b0 = b1 = b2 = 1.0
        pdf = 0.0
        lr = lg = lb = 0.0
        for bounce in range(max_bounces):
            tri, t, u, v = intersect1(fn_hit, scene, words, ints, addr, ox, oy, oz,
                                      dx, dy, dz, NO_HIT_TMAX)
            rays += 1
            if bounce == 0 and s == first:
                counts[k, 1] = 1 if tri >= 0 else 0
            if tri < 0:
                lr += b0 * background[0]
                lg += b1 * background[1]
                lb += b2 * background[2]
                break
            # The surface frame (surface_rays.surface_frame)
            w0 = 1.0 - u - v
            px, py, pz = ox + t * dx, oy + t * dy, oz + t * dz
            nx = (w0 * corner_normals[tri, 0, 0] + u * corner_normals[tri, 1, 0]
                  + v * corner_normals[tri, 2, 0])
            ny = (w0 * corner_normals[tri, 0, 1] + u * corner_normals[tri, 1, 1]
                  + v * corner_normals[tri, 2, 1])
            nz = (w0 * corner_normals[tri, 0, 2] + u * corner_normals[tri, 1, 2]
                  + v * corner_normals[tri, 2, 2])
            side = (face_normals[tri, 0] * dx + face_normals[tri, 1] * dy
                    + face_normals[tri, 2] * dz)
            nl = math.sqrt(nx ** 2 + ny ** 2 + nz ** 2)
            sign = 1.0 if side < 0.0 else -1.0
            entering = side < 0.0
            nl = max(nl, 1e-300)
            nx, ny, nz = sign * nx / nl, sign * ny / nl, sign * nz / nl
            gx = sign * face_normals[tri, 0]
            gy = sign * face_normals[tri, 1]
            gz = sign * face_normals[tri, 2]
            m = object_material[object_index[tri]]
            # Emission, MIS-weighted after a diffuse or glossy bounce
            if max(emission[m, 0], max(emission[m, 1], emission[m, 2])) > 0.0:
                w = _emission_weight(pdf, t, abs(gx * dx + gy * dy + gz * dz),
                                     em_area)
                lr += b0 * emission[m, 0] * w
                lg += b1 * emission[m, 1] * w
                lb += b2 * emission[m, 2] * w
            p_d = (rho[m, 0] + rho[m, 1] + rho[m, 2]) / 3.0
            p_s = p_glossy[m]
            total = p_d + kr[m] + kt[m] + p_s
            prob_d = p_d / total if total > 0.0 else 0.0
            prob_s = p_s / total if total > 0.0 else 0.0
            u0, u1, u2, u_lobe, d1, d2, u_rr = vertex_draws(ps, s, bounce, em_cdf)
            # Next-event estimation: one point on the emitters, by area
            if n_em > 0 and (p_d > 0.0 or p_s > 0.0):
                (ok, sx, sy, sz, wx, wy, wz, tmax, c0, c1, c2) = next_event_ray(
                    m, emitters, rho, lobes, b0, b1, b2, px, py, pz, nx, ny, nz, gx, gy, gz,
                    -dx, -dy, -dz, prob_d, prob_s, blinn, eps, u0, u1, u2)
                if ok:
                    rays += 1
                    if not occluded1(fn_occ, scene, words, ints, addr, sx, sy, sz,
                                     wx, wy, wz, min(tmax, T_INF)):
                        lr += c0
                        lg += c1
                        lb += c2
            if total <= 0.0:
                break
            (alive, ox, oy, oz, dx, dy, dz, b0, b1, b2, pdf) = continue_path(
                m, surfaces, lobes, b0, b1, b2, px, py, pz, nx, ny, nz, gx, gy, gz, dx, dy,
                dz, entering, p_d, p_s, total, prob_d, prob_s, eps, (u_lobe, d1, d2, u_rr),
                bounce >= rr_start, blinn)
            if not alive:
                break
        total_r += lr
        total_g += lg
        total_b += lb
    out[k, 0], out[k, 1], out[k, 2] = total_r, total_g, total_b
    counts[k, 0] = rays
