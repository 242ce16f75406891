"""One path-tracer vertex per path, in numba: emission (MIS-weighted), next-event
estimation, lobe choice (diffuse, glossy, mirror, glass) and Russian roulette. Mirrors
``PathTracer`` (see :mod:`shadelab.raytrace.pathtrace` for the estimator); the glossy lobe is
:mod:`shadelab.raytrace.glossy`'s. A material without a glossy lobe (ks = 0) draws and
computes exactly what a diffuse-only vertex does (tests/raytrace/test_pathtrace_glossy.py).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from shadelab.raytrace.glossy import lobe_pdf, sample_lobe
from shadelab.raytrace.scatter import (
    _fr_dielectric,
    _ior_pair,
    _reflect,
    _refract,
    _sample_cosine_hemisphere,
)


@nb.njit(cache=True, inline="always")
def _emission_weight(bsdf_pdf, t, cos_y, em_area):
    """MIS weight (balance heuristic) of emission reached by a BSDF sample, against area
    sampling of the emitters; 1 after a specular bounce (pdf 0)."""
    if not bsdf_pdf > 0.0:
        return 1.0
    light_pdf = t * t / max(cos_y * em_area, 1e-300)
    return bsdf_pdf / (bsdf_pdf + light_pdf)


@nb.njit(cache=True, inline="always")
def _specular_lobe(u, p_d, kr, kt, ior, entering, total, dx, dy, dz, nx, ny, nz, u_fresnel):
    """Mirror or glass (Fresnel picks reflection or refraction): direction, side of the
    surface the new ray leaves from (1 front, -1 through), weight and lobe probability."""
    cos_i = min(max(-(dx * nx + dy * ny + dz * nz), 0.0), 1.0)
    ox, oy, oz = _reflect(dx, dy, dz, nx, ny, nz, cos_i)
    if u < p_d + kr:  # mirror
        return ox, oy, oz, 1.0, kr, kr / total
    n1, n2 = _ior_pair(entering, ior)
    f, cos_t, _ = _fr_dielectric(cos_i, n1, n2)
    if u_fresnel >= f:
        ox, oy, oz = _refract(dx, dy, dz, nx, ny, nz, n1 / n2, cos_i, cos_t)
        return ox, oy, oz, -1.0, kt, kt / total
    return ox, oy, oz, 1.0, kt, kt / total


@nb.njit(cache=True, inline="always")
def next_event_ray(m, emitters, rho, lobes, b0, b1, b2, px, py, pz, nx, ny, nz, gx, gy, gz,
                   vx, vy, vz, prob_d, prob_s, blinn, eps, u0, u1, u2):
    """Next-event estimation at one vertex: a shadow ray to one point on the emitters, chosen
    by area (u0 the triangle, u1, u2 its barycentrics); the diffuse and glossy parts each
    MIS-weighted against their own lobe's pdf. Returns (ok, origin, direction, tmax, the
    contribution beta f Le cos / pdf if unoccluded); ok is False where no ray is cast."""
    em_cdf, em_p0, em_e1, em_e2, em_normal, em_le, em_area = emitters
    k = np.searchsorted(em_cdf, u0, side="right")
    k = min(k, len(em_cdf) - 1)
    s = math.sqrt(u1)
    a, b = s * (1.0 - u2), s * u2
    qx = em_p0[k, 0] + a * em_e1[k, 0] + b * em_e2[k, 0] - px
    qy = em_p0[k, 1] + a * em_e1[k, 1] + b * em_e2[k, 1] - py
    qz = em_p0[k, 2] + a * em_e1[k, 2] + b * em_e2[k, 2] - pz
    dist = math.sqrt(qx * qx + qy * qy + qz * qz)
    if not dist > 2.0 * eps:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    wx, wy, wz = qx / dist, qy / dist, qz / dist
    cos_x = nx * wx + ny * wy + nz * wz
    cos_y = abs(em_normal[k, 0] * wx + em_normal[k, 1] * wy + em_normal[k, 2] * wz)
    if not (cos_x > 0.0 and gx * wx + gy * wy + gz * wz > 0.0):
        return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    light_pdf = dist * dist / max(cos_y * em_area, 1e-300)
    scale = cos_x / (light_pdf + prob_d * cos_x / math.pi) / math.pi
    c0 = b0 * rho[m, 0] * em_le[k, 0] * scale
    c1 = b1 * rho[m, 1] * em_le[k, 1] * scale
    c2 = b2 * rho[m, 2] * em_le[k, 2] * scale
    if prob_s > 0.0:  # f_s cos = ks Os lobe / pi
        ks_os, shininess = lobes[0], lobes[1]
        lobe, pdf = lobe_pdf(wx, wy, wz, nx, ny, nz, vx, vy, vz, shininess[m], blinn)
        glossy = lobe / math.pi / (light_pdf + prob_s * pdf)
        c0 += b0 * ks_os[m, 0] * em_le[k, 0] * glossy
        c1 += b1 * ks_os[m, 1] * em_le[k, 1] * glossy
        c2 += b2 * ks_os[m, 2] * em_le[k, 2] * glossy
    return (True, px + eps * gx, py + eps * gy, pz + eps * gz, wx, wy, wz,
            dist * (1.0 - 1e-4) - 2.0 * eps, c0, c1, c2)


@nb.njit(cache=True)
def _next_event(i, m, emitters, rho, lobes, beta, px, py, pz, nx, ny, nz, gx, gy, gz,
                vx, vy, vz, prob_d, prob_s, blinn, eps, rnd, nee_o, nee_d, nee_t, nee_ok,
                nee_val):
    """:func:`next_event_ray` for path i, written into the batch's rows."""
    (ok, ox, oy, oz, wx, wy, wz, tmax, c0, c1, c2) = next_event_ray(
        m, emitters, rho, lobes, beta[i, 0], beta[i, 1], beta[i, 2], px, py, pz, nx, ny, nz,
        gx, gy, gz, vx, vy, vz, prob_d, prob_s, blinn, eps, rnd[i, 0], rnd[i, 1], rnd[i, 2])
    if not ok:
        return
    nee_ok[i] = True
    nee_o[i, 0], nee_o[i, 1], nee_o[i, 2] = ox, oy, oz
    nee_d[i, 0], nee_d[i, 1], nee_d[i, 2] = wx, wy, wz
    nee_t[i] = tmax
    nee_val[i, 0], nee_val[i, 1], nee_val[i, 2] = c0, c1, c2


@nb.njit(cache=True, inline="always")
def continue_path(m, surfaces, lobes, b0, b1, b2, px, py, pz, nx, ny, nz, gx, gy, gz,
                  dx, dy, dz, entering, p_d, p_s, total, prob_d, prob_s, eps, uniforms,
                  roulette, blinn):
    """Pick a lobe (diffuse, glossy, mirror, glass: their weights p_d, p_s, kr, kt of
    ``total`` > 0), sample it, and play Russian roulette: (alive, new origin, direction,
    throughput, pdf of the direction for MIS: 0 after a mirror or glass bounce).
    ``uniforms`` = (lobe, 2 direction, roulette). Fewer than 31 parameters: CPython passes
    a longer call's arguments as *args, which numba cannot inline."""
    u_lobe, u1, u2, u_roulette = uniforms
    rho, kr, kt, ior, emission = surfaces
    ks_os, shininess, p_glossy = lobes
    u = u_lobe * total
    side = 1.0
    pdf = 0.0
    if u < p_d:  # diffuse: cosine-weighted about the shading normal, weight rho / P
        ox, oy, oz, cos_o = _sample_cosine_hemisphere(u1, u2, nx, ny, nz)
        if ox * gx + oy * gy + oz * gz <= 0.0:
            return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        c0 = b0 * rho[m, 0] / prob_d
        c1 = b1 * rho[m, 1] / prob_d
        c2 = b2 * rho[m, 2] / prob_d
        pdf = prob_d * cos_o / math.pi
    elif p_s > 0.0 and u < p_d + p_s:  # glossy: the lobe, weight ks Os (f cos / pdf) / P
        ox, oy, oz, weight = sample_lobe(u1, u2, nx, ny, nz, -dx, -dy, -dz, shininess[m],
                                         blinn)
        if not (weight > 0.0 and ox * gx + oy * gy + oz * gz > 0.0
                and ox * nx + oy * ny + oz * nz > 0.0):
            return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        c0 = b0 * ks_os[m, 0] * weight / prob_s
        c1 = b1 * ks_os[m, 1] * weight / prob_s
        c2 = b2 * ks_os[m, 2] * weight / prob_s
        _, lpdf = lobe_pdf(ox, oy, oz, nx, ny, nz, -dx, -dy, -dz, shininess[m], blinn)
        pdf = prob_s * lpdf
    else:
        ox, oy, oz, side, weight, prob = _specular_lobe(u, p_d + p_s, kr[m], kt[m], ior[m],
                                                        entering, total, dx, dy, dz,
                                                        nx, ny, nz, u1)
        c0 = b0 * weight / prob
        c1 = b1 * weight / prob
        c2 = b2 * weight / prob
    # Russian roulette
    if roulette:
        q = min(max(c0, max(c1, c2)), 0.95)
        if u_roulette >= q:
            return False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        c0 /= max(q, 1e-12)
        c1 /= max(q, 1e-12)
        c2 /= max(q, 1e-12)
    return (True, px + side * eps * gx, py + side * eps * gy, pz + side * eps * gz, ox, oy, oz,
            c0, c1, c2, pdf)


@nb.njit(cache=True, parallel=True)
def path_vertex(out, pixel, beta, bsdf_pdf, position, normal, geo, entering, dirs, t, mat,
                surfaces, lobes, emitters, eps, rnd, roulette, blinn):
    """One path vertex per path: emission (MIS-weighted), next-event set-up, lobe choice.

    Mirrors ``PathTracer`` (see :mod:`shadelab.raytrace.pathtrace` for the estimator).
    ``surfaces`` = (rho, kr, kt, ior, emission) per material; ``lobes`` = (ks Os, n, glossy
    lobe weight) per material (:func:`lobe_weight`); ``emitters`` = (cdf, p0, e1, e2, normal,
    le, total area) of the emitting triangles; ``blinn`` picks (N.H)^n over (R.V)^n. ``rnd``
    holds 7 uniforms per path: emitter, 2 barycentrics, lobe, 2 direction, roulette. The
    lobes are picked in the order diffuse, glossy, mirror, glass: a material without a glossy
    lobe draws and computes exactly what a diffuse-only vertex does.
    Returns the shadow rays of next-event estimation (origins, dirs, tmax, candidate flag,
    unoccluded contribution) and the continued paths (origins, dirs, beta, pdf, alive).
    """
    rho, kr, kt, ior, emission = surfaces
    ks_os, shininess, p_glossy = lobes
    em_area = emitters[6]
    n = len(pixel)
    nee_o = np.empty((n, 3))
    nee_d = np.empty((n, 3))
    nee_t = np.empty(n)
    nee_ok = np.zeros(n, np.bool_)
    nee_val = np.zeros((n, 3))
    new_o = np.empty((n, 3))
    new_d = np.empty((n, 3))
    new_beta = np.empty((n, 3))
    new_pdf = np.zeros(n)
    alive = np.zeros(n, np.bool_)
    n_em = len(emitters[0])
    for i in nb.prange(n):  # each path writes its own rows (``pixel`` has no repeats)
        m = mat[i]
        px, py, pz = position[i, 0], position[i, 1], position[i, 2]
        nx, ny, nz = normal[i, 0], normal[i, 1], normal[i, 2]
        gx, gy, gz = geo[i, 0], geo[i, 1], geo[i, 2]
        dx, dy, dz = dirs[i, 0], dirs[i, 1], dirs[i, 2]
        # Emission, MIS-weighted after a diffuse or glossy bounce
        if max(emission[m, 0], max(emission[m, 1], emission[m, 2])) > 0.0:
            w = _emission_weight(bsdf_pdf[i], t[i], abs(gx * dx + gy * dy + gz * dz), em_area)
            for c in range(3):
                out[pixel[i], c] += beta[i, c] * emission[m, c] * w
        p_d = (rho[m, 0] + rho[m, 1] + rho[m, 2]) / 3.0
        p_s = p_glossy[m]
        total = p_d + kr[m] + kt[m] + p_s
        prob_d = p_d / total if total > 0.0 else 0.0
        prob_s = p_s / total if total > 0.0 else 0.0
        # Next-event estimation: one point on the emitters, by area
        if n_em > 0 and (p_d > 0.0 or p_s > 0.0):
            _next_event(i, m, emitters, rho, lobes, beta, px, py, pz, nx, ny, nz, gx, gy, gz,
                        -dx, -dy, -dz, prob_d, prob_s, blinn, eps, rnd, nee_o, nee_d, nee_t,
                        nee_ok, nee_val)
        if total <= 0.0:
            continue
        (alive[i], new_o[i, 0], new_o[i, 1], new_o[i, 2], new_d[i, 0], new_d[i, 1],
         new_d[i, 2], new_beta[i, 0], new_beta[i, 1], new_beta[i, 2],
         new_pdf[i]) = continue_path(m, surfaces, lobes, beta[i, 0], beta[i, 1], beta[i, 2],
                                     px, py, pz, nx, ny, nz, gx, gy, gz, dx, dy, dz,
                                     entering[i], p_d, p_s, total, prob_d, prob_s, eps,
                                     (rnd[i, 3], rnd[i, 4], rnd[i, 5], rnd[i, 6]), roulette,
                                     blinn)
    return nee_o, nee_d, nee_t, nee_ok, nee_val, new_o, new_d, new_beta, new_pdf, alive

