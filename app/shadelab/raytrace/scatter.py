"""Scattering helpers shared by Whitted's ray spawning (:mod:`shadelab.raytrace.rays`) and
the path tracer's vertex (:mod:`shadelab.raytrace.vertex`), in numba.

pbrt-v4's names: Reflect, FrDielectric, Refract, SampleCosineHemisphere. Inlined, so the
callers compile to what they were when these lines were written out in each of them.
"""

from __future__ import annotations

import math

import numba as nb


@nb.njit(cache=True, inline="always")
def _ior_pair(entering, ior):
    """(n1, n2): from air into the medium when entering, out of it otherwise."""
    if entering:
        return 1.0, ior
    return ior, 1.0


@nb.njit(cache=True, inline="always")
def _reflect(dx, dy, dz, nx, ny, nz, cos_i):
    """Unit mirror direction of the incident ray d about n (cos_i = -d.n, clamped)."""
    rx, ry, rz = dx + 2.0 * cos_i * nx, dy + 2.0 * cos_i * ny, dz + 2.0 * cos_i * nz
    length = math.sqrt(rx * rx + ry * ry + rz * rz)
    return rx / length, ry / length, rz / length


@nb.njit(cache=True, inline="always")
def _fr_dielectric(cos_i, n1, n2):
    """Fresnel reflectance F of unpolarized light (1 under total internal reflection), the
    cosine of the refracted ray (0 under TIR) and whether TIR happens."""
    eta = n1 / n2
    k = 1.0 - eta * eta * (1.0 - cos_i * cos_i)
    tir = k < 0.0
    cos_t = math.sqrt(max(k, 0.0))
    if tir:
        return 1.0, cos_t, tir
    rs = (n1 * cos_i - n2 * cos_t) / max(n1 * cos_i + n2 * cos_t, 1e-300)
    rp = (n2 * cos_i - n1 * cos_t) / max(n2 * cos_i + n1 * cos_t, 1e-300)
    return 0.5 * (rs * rs + rp * rp), cos_t, tir


@nb.njit(cache=True, inline="always")
def _refract(dx, dy, dz, nx, ny, nz, eta, cos_i, cos_t):
    """Unit refracted direction (Snell: eta = n1 / n2) of the incident ray d through n."""
    a = eta * cos_i - cos_t
    tx, ty, tz = eta * dx + a * nx, eta * dy + a * ny, eta * dz + a * nz
    length = math.sqrt(tx * tx + ty * ty + tz * tz)
    return tx / length, ty / length, tz / length


@nb.njit(cache=True, inline="always")
def _sample_cosine_hemisphere(u1, u2, nx, ny, nz):
    """A cosine-weighted direction about the unit n (Malley: a disk point lifted) and its
    cosine with n (pdf = cos / pi). The frame is Duff et al.'s branchless ONB."""
    r = math.sqrt(u1)
    phi = 2.0 * math.pi * u2
    lx, ly, lz = r * math.cos(phi), r * math.sin(phi), math.sqrt(max(1.0 - u1, 0.0))
    sign = 1.0 if nz >= 0.0 else -1.0
    aa = -1.0 / (sign + nz)
    bb = nx * ny * aa
    tx, ty, tz = 1.0 + sign * nx * nx * aa, sign * bb, -sign * nx
    bx, by, bz = bb, sign + ny * ny * aa, -ny
    ox = lx * tx + ly * bx + lz * nx
    oy = lx * ty + ly * by + lz * ny
    oz = lx * tz + ly * bz + lz * nz
    return ox, oy, oz, lz

