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

:func:`shadelab.raytrace.vertex.path_vertex` is the path tracer's numba vertex, with this
lobe beside the diffuse, mirror and glass ones; the numpy twin is ``PathTracer.radiance``.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from shadelab.constants import SHADING_EPS as EPS
from shadelab.raytrace.scatter import _sample_cosine_hemisphere
from shadelab.shading.kernels import _power


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
