"""The lecture's specular term as a BRDF, and the path tracer's vertex with its sampled lobe.

A delta light's direct term in the path tracer is the lecture's ks Os (R.V)^n (Phong) or
ks Os (N.H)^n (Blinn-Phong), with no normalization factor, a lecture light of intensity Ip
being a point source of radiant intensity pi Ip (:mod:`shadelab.raytrace.pathtrace`). The one
BRDF whose delta-light contribution f cos(theta_i) pi Ip is exactly that term is

    f_s(wi, wo) = ks Os lobe(wi) / (pi cos theta_i),  lobe = (R.wi)^n,  R = 2 N (N.V) - V
                                                      or (N.H)^n,  H = (wi + V) / |wi + V|

(Phong's original BRDF with the lecture's ks: R_L.V = R_V.L, so the Phong lobe is symmetric,
but the 1 / cos theta_i is not reciprocal). It is deliberately not the modified Phong
normalization (n + 2) / (2 pi) cos^n: that BRDF's delta-light term would be the lecture's
times (n + 2) cos(theta_i) / 2, and the path tracer's first bounce would no longer be the
raster's and Whitted's image. The energy stays bounded: the directional albedo
a(wo) = ks Os / pi * integral over the hemisphere of lobe(wi) dwi is largest at normal
incidence, 2 ks Os / (n + 1) for Phong and 8 ks Os (1 - 2^-(n/2 + 1)) / (n + 2) for
Blinn-Phong (:func:`lobe_weight`); with the diffuse, mirror and glass lobes a material
conserves energy while kd Od + a + kr + kt <= 1.

Sampling, pdfs in solid angle (``V`` = -d, the unit vector to the eye; u1, u2 uniform):

- Phong: wi about R with cos(alpha) = u1^(1/(n+1)), pdf (n + 1) / (2 pi) (R.wi)^n, so
  f cos / pdf = 2 ks Os / (n + 1);
- Blinn-Phong: H about N the same way, wi = 2 (V.H) H - V, pdf (n + 1) / (2 pi) (N.H)^n / (4 V.H),
  so f cos / pdf = 8 ks Os (V.H) / (n + 1);
- a direction below the shading or the geometric surface (or V.H <= 0) ends the path: the
  BRDF is 0 there, so the estimator stays unbiased.

:func:`path_vertex` is the path tracer's numba vertex (``kernels.path_vertex`` with this lobe
beside the diffuse, mirror and glass ones); the numpy twin is ``PathTracer.radiance``.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from shadelab.constants import SHADING_EPS as EPS
from shadelab.raytrace.kernels import (
    _emission_weight,
    _power,
    _sample_cosine_hemisphere,
    _specular_lobe,
)


def lobe_weight(ks_os_mean: np.ndarray, shininess: np.ndarray, blinn: bool) -> np.ndarray:
    """Probability weight of each material's glossy lobe (beside mean(rho), kr and kt): its
    albedo at normal incidence, mean(ks Os) 2 / (n + 1) or 8 (1 - 2^-(n/2+1)) / (n + 2)."""
    n = np.asarray(shininess, dtype=np.float64)
    if blinn:
        albedo = 8.0 * (1.0 - 2.0 ** (-(n / 2.0 + 1.0))) / (n + 2.0)
    else:
        albedo = 2.0 / (n + 1.0)
    return np.asarray(ks_os_mean, dtype=np.float64) * albedo


@nb.njit(cache=True, inline="always")
def _mirror_axis(nx, ny, nz, vx, vy, vz):
    """R = 2 N (N.V) - V, the mirror direction of the eye vector (unit for unit N, V)."""
    c = nx * vx + ny * vy + nz * vz
    return 2.0 * c * nx - vx, 2.0 * c * ny - vy, 2.0 * c * nz - vz


@nb.njit(cache=True, inline="always")
def lobe_pdf(wx, wy, wz, nx, ny, nz, vx, vy, vz, shininess, blinn):
    """lobe(wi) (as the direct term computes it) and the pdf of sampling wi (solid angle)."""
    if blinn:
        hx, hy, hz = wx + vx, wy + vy, wz + vz
        hl = math.sqrt(hx * hx + hy * hy + hz * hz)
        if not hl > EPS:
            return 0.0, 0.0
        vh = (vx * hx + vy * hy + vz * hz) / hl
        lobe = _power((nx * hx + ny * hy + nz * hz) / hl, shininess)
        if not vh > 0.0:
            return lobe, 0.0
        return lobe, (shininess + 1.0) / (2.0 * math.pi) * lobe / (4.0 * vh)
    rx, ry, rz = _mirror_axis(nx, ny, nz, vx, vy, vz)
    lobe = _power(rx * wx + ry * wy + rz * wz, shininess)
    return lobe, (shininess + 1.0) / (2.0 * math.pi) * lobe


@nb.njit(cache=True, inline="always")
def sample_lobe(u1, u2, nx, ny, nz, vx, vy, vz, shininess, blinn):
    """A direction wi from the lobe and f cos / pdf per unit ks Os (0: rejected, V.H <= 0).

    cos(alpha) = u1^(1/(n+1)) about the axis (R, or N for the half vector); the cosine
    sampler with 1 - cos^2(alpha) in place of its first uniform puts it in the same frame."""
    cos_a = u1 ** (1.0 / (shininess + 1.0))
    u_disk = 1.0 - cos_a * cos_a
    if blinn:
        hx, hy, hz, _ = _sample_cosine_hemisphere(u_disk, u2, nx, ny, nz)
        vh = vx * hx + vy * hy + vz * hz
        wx, wy, wz = 2.0 * vh * hx - vx, 2.0 * vh * hy - vy, 2.0 * vh * hz - vz
        return wx, wy, wz, 8.0 * max(vh, 0.0) / (shininess + 1.0)
    rx, ry, rz = _mirror_axis(nx, ny, nz, vx, vy, vz)
    wx, wy, wz, _ = _sample_cosine_hemisphere(u_disk, u2, rx, ry, rz)
    return wx, wy, wz, 2.0 / (shininess + 1.0)


@nb.njit(cache=True)
def _next_event(i, m, emitters, rho, lobes, beta, px, py, pz, nx, ny, nz, gx, gy, gz,
                vx, vy, vz, prob_d, prob_s, blinn, eps, rnd, nee_o, nee_d, nee_t, nee_ok,
                nee_val):
    """Next-event estimation: a shadow ray to one point on the emitters, chosen by area; the
    diffuse and glossy parts each MIS-weighted against their own lobe's pdf."""
    em_cdf, em_p0, em_e1, em_e2, em_normal, em_le, em_area = emitters
    k = np.searchsorted(em_cdf, rnd[i, 0], side="right")
    k = min(k, len(em_cdf) - 1)
    s = math.sqrt(rnd[i, 1])
    a, b = s * (1.0 - rnd[i, 2]), s * rnd[i, 2]
    qx = em_p0[k, 0] + a * em_e1[k, 0] + b * em_e2[k, 0] - px
    qy = em_p0[k, 1] + a * em_e1[k, 1] + b * em_e2[k, 1] - py
    qz = em_p0[k, 2] + a * em_e1[k, 2] + b * em_e2[k, 2] - pz
    dist = math.sqrt(qx * qx + qy * qy + qz * qz)
    if not dist > 2.0 * eps:
        return
    wx, wy, wz = qx / dist, qy / dist, qz / dist
    cos_x = nx * wx + ny * wy + nz * wz
    cos_y = abs(em_normal[k, 0] * wx + em_normal[k, 1] * wy + em_normal[k, 2] * wz)
    if not (cos_x > 0.0 and gx * wx + gy * wy + gz * wz > 0.0):
        return
    light_pdf = dist * dist / max(cos_y * em_area, 1e-300)
    scale = cos_x / (light_pdf + prob_d * cos_x / math.pi) / math.pi
    nee_ok[i] = True
    nee_o[i, 0] = px + eps * gx
    nee_o[i, 1] = py + eps * gy
    nee_o[i, 2] = pz + eps * gz
    nee_d[i, 0], nee_d[i, 1], nee_d[i, 2] = wx, wy, wz
    nee_t[i] = dist * (1.0 - 1e-4) - 2.0 * eps
    for c in range(3):
        nee_val[i, c] = beta[i, c] * rho[m, c] * em_le[k, c] * scale
    if prob_s > 0.0:  # f_s cos = ks Os lobe / pi
        ks_os, shininess = lobes[0], lobes[1]
        lobe, pdf = lobe_pdf(wx, wy, wz, nx, ny, nz, vx, vy, vz, shininess[m], blinn)
        glossy = lobe / math.pi / (light_pdf + prob_s * pdf)
        for c in range(3):
            nee_val[i, c] += beta[i, c] * ks_os[m, c] * em_le[k, c] * glossy


@nb.njit(cache=True)
def path_vertex(out, pixel, beta, bsdf_pdf, position, normal, geo, entering, dirs, t, mat,
                surfaces, lobes, emitters, eps, rnd, roulette, blinn):
    """One path vertex per path: emission (MIS-weighted), next-event set-up, lobe choice.

    Mirrors ``PathTracer`` (see :mod:`shadelab.raytrace.pathtrace` for the estimator).
    ``surfaces`` = (rho, kr, kt, ior, emission) per material; ``lobes`` = (ks Os, n, glossy
    lobe weight) per material (:func:`lobe_weight`); ``emitters`` = (cdf, p0, e1, e2, normal,
    le, total area) of the emitting triangles; ``blinn`` picks (N.H)^n over (R.V)^n. ``rnd``
    holds 7 uniforms per path: emitter, 2 barycentrics, lobe, 2 direction, roulette. The
    lobes are picked in the order diffuse, glossy, mirror, glass: a material without a glossy
    lobe draws and computes exactly what ``kernels.path_vertex`` does.
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
    for i in range(n):
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
        # Pick a lobe
        u = rnd[i, 3] * total
        side = 1.0
        if u < p_d:  # diffuse: cosine-weighted about the shading normal, weight rho / P
            ox, oy, oz, cos_o = _sample_cosine_hemisphere(rnd[i, 4], rnd[i, 5], nx, ny, nz)
            if ox * gx + oy * gy + oz * gz <= 0.0:
                continue
            for c in range(3):
                new_beta[i, c] = beta[i, c] * rho[m, c] / prob_d
            new_pdf[i] = prob_d * cos_o / math.pi
        elif p_s > 0.0 and u < p_d + p_s:  # glossy: the lobe, weight ks Os (f cos / pdf) / P
            ox, oy, oz, weight = sample_lobe(rnd[i, 4], rnd[i, 5], nx, ny, nz, -dx, -dy, -dz,
                                             shininess[m], blinn)
            if not (weight > 0.0 and ox * gx + oy * gy + oz * gz > 0.0
                    and ox * nx + oy * ny + oz * nz > 0.0):
                continue
            for c in range(3):
                new_beta[i, c] = beta[i, c] * ks_os[m, c] * weight / prob_s
            _, pdf = lobe_pdf(ox, oy, oz, nx, ny, nz, -dx, -dy, -dz, shininess[m], blinn)
            new_pdf[i] = prob_s * pdf
        else:
            ox, oy, oz, side, weight, prob = _specular_lobe(u, p_d + p_s, kr[m], kt[m], ior[m],
                                                            entering[i], total, dx, dy, dz,
                                                            nx, ny, nz, rnd[i, 4])
            for c in range(3):
                new_beta[i, c] = beta[i, c] * weight / prob
        # Russian roulette
        if roulette:
            q = min(max(new_beta[i, 0], max(new_beta[i, 1], new_beta[i, 2])), 0.95)
            if rnd[i, 6] >= q:
                continue
            for c in range(3):
                new_beta[i, c] /= max(q, 1e-12)
        alive[i] = True
        new_d[i, 0], new_d[i, 1], new_d[i, 2] = ox, oy, oz
        new_o[i, 0] = px + side * eps * gx
        new_o[i, 1] = py + side * eps * gy
        new_o[i, 2] = pz + side * eps * gz
    return nee_o, nee_d, nee_t, nee_ok, nee_val, new_o, new_d, new_beta, new_pdf, alive
