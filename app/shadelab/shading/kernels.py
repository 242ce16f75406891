"""The lecture's local model in numba, for speed: :func:`local_shade` mirrors
:func:`shadelab.shading.reference.shade` term by term (same guards: EPS = 1e-12, pow only
where the cosine is positive, f_att = 1 at infinite distance);
``tests/raytrace/test_raytrace_kernels.py`` holds the two together on random inputs. The
tracers use these kernels by default and the numpy reference with
``TraceContext(local="numpy")``. The tables come from :mod:`shadelab.shading.packing`
(:func:`~shadelab.shading.packing.material_table`, :func:`~shadelab.shading.packing.light_table`).

A light kind's branch is :func:`_to_light` (to-light vector and distance) and the spot cone in
:func:`local_shade_into3` (the numba twins of :mod:`shadelab.shading.lights`).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from shadelab.constants import SHADING_EPS as EPS
from shadelab.shading.codes import ATTENUATION_CODES, LIGHT_KIND_CODES
from shadelab.shading.packing import (
    L_ATT,
    L_C1,
    L_C2,
    L_C3,
    L_COS,
    L_DIR,
    L_EXP,
    L_IP,
    L_KIND,
    L_POS,
    M_KA,
    M_KD,
    M_KS,
    M_LE,
    M_N,
    M_OD,
    M_OS,
)

# The codes as the light table stores them (float64); numba freezes them at compile time
_DIRECTIONAL = float(LIGHT_KIND_CODES["directional"])
_SPOT = float(LIGHT_KIND_CODES["spot"])
_ATT_NONE = float(ATTENUATION_CODES["none"])
_ATT_INVERSE_SQUARE = float(ATTENUATION_CODES["inverse_square"])


@nb.njit(cache=True, inline="always")
def _to_light(lights, k, px, py, pz):
    """Unit vector to light k and its distance (inf for a directional light)."""
    if lights[k, L_KIND] == _DIRECTIONAL:
        dx, dy, dz = -lights[k, L_DIR], -lights[k, L_DIR + 1], -lights[k, L_DIR + 2]
        length = math.sqrt(dx * dx + dy * dy + dz * dz)
        if length > EPS:
            return dx / length, dy / length, dz / length, np.inf
        return 0.0, 0.0, 0.0, np.inf
    dx = lights[k, L_POS] - px
    dy = lights[k, L_POS + 1] - py
    dz = lights[k, L_POS + 2] - pz
    length = math.sqrt(dx * dx + dy * dy + dz * dz)
    if length > EPS:
        return dx / length, dy / length, dz / length, length
    return 0.0, 0.0, 0.0, length


@nb.njit(cache=True, inline="always")
def _power(c, n):
    if c > 0.0:
        return max(c, EPS) ** n
    return 0.0


@nb.njit(cache=True, inline="always")
def _lit(ip, kd, od, lam, ks, os_, spec):
    """One channel of a light's diffuse + specular term (the same products as reference)."""
    return ip * kd * od * lam + ip * ks * os_ * spec


# local_shade and local_shade_into are plain Python: the parallel kernel below is entered from
# Python only. Called from a cached serial njit function, a parallel kernel crashed a fresh
# process that loaded both from numba's cache before any parallel kernel had started the
# thread pool (numba issue 8578; segfault seen in a clean clone's CI run).
def local_shade(position, normal, to_eye, mat, mats, lights, ia, blinn, shadow):
    """The lecture's I (N, 3) at N points; ``shadow`` is (L, N) S_i."""
    out = np.empty((len(position), 3))
    local_shade_into(out, position, normal, to_eye, mat, mats, lights, ia, blinn, shadow, -1.0)
    return out


def local_shade_into(out, position, normal, to_eye, mat, mats, lights, ia, blinn, shadow,
                     eye_sign):
    """:func:`local_shade` into ``out`` (N, 3); the vector to the eye is ``-eye_sign * to_eye``
    (pass the ray directions with ``eye_sign = 1``, so no negated copy is made). ``shadow`` is
    (L, N): :func:`local_shade_into3` with one S_i for every channel (a view, no copy)."""
    shadow = np.asarray(shadow, dtype=np.float64)
    local_shade_into3(out, position, normal, to_eye, mat, mats, lights, ia, blinn,
                      shadow.reshape((shadow.shape[0], shadow.shape[1], 1)), float(eye_sign))


@nb.njit(cache=True, parallel=True)
def local_shade_into3(out, position, normal, to_eye, mat, mats, lights, ia, blinn, shadow,
                      eye_sign):
    """The lecture's I (N, 3) into ``out`` with S_i per light and point: ``shadow`` is
    (L, N, 3), the kt-filtered transmittance of each shadow ray per channel, or (L, N, 1), one
    S_i for all three (:func:`local_shade_into`). The vector to the eye is
    ``-eye_sign * to_eye``."""
    n_points = len(position)
    w = shadow.shape[2]   # 3 channels, or 1 shared by all
    for i in nb.prange(n_points):
        m = mat[i]
        px, py, pz = position[i, 0], position[i, 1], position[i, 2]
        nx, ny, nz = normal[i, 0], normal[i, 1], normal[i, 2]
        if eye_sign > 0.0:
            vx, vy, vz = -to_eye[i, 0], -to_eye[i, 1], -to_eye[i, 2]
        else:
            vx, vy, vz = to_eye[i, 0], to_eye[i, 1], to_eye[i, 2]
        ka, kd, ks, shininess = mats[m, M_KA], mats[m, M_KD], mats[m, M_KS], mats[m, M_N]
        r0 = mats[m, M_LE] + ia[0] * ka * mats[m, M_OD]
        r1 = mats[m, M_LE + 1] + ia[1] * ka * mats[m, M_OD + 1]
        r2 = mats[m, M_LE + 2] + ia[2] * ka * mats[m, M_OD + 2]
        for k in range(len(lights)):
            s0, s1, s2 = shadow[k, i, 0], shadow[k, i, 1 % w], shadow[k, i, 2 % w]
            if (kd == 0.0 and ks == 0.0) or (s0 == 0.0 and s1 == 0.0 and s2 == 0.0):
                continue  # adds exactly 0 (mirror, glass, or a shadowed light)
            lx, ly, lz, dist = _to_light(lights, k, px, py, pz)
            # f_att
            att = lights[k, L_ATT]
            if not math.isfinite(dist) or att == _ATT_NONE:
                f_att = 1.0
            elif att == _ATT_INVERSE_SQUARE:
                f_att = 1.0 / max(dist * dist, EPS)
            else:
                den = lights[k, L_C1] + lights[k, L_C2] * dist + lights[k, L_C3] * dist * dist
                f_att = min(1.0 / max(den, EPS), 1.0)
            # spot cone
            spot = 1.0
            if lights[k, L_KIND] == _SPOT:
                cos_phi = -(lx * lights[k, L_DIR] + ly * lights[k, L_DIR + 1]
                            + lz * lights[k, L_DIR + 2])
                if cos_phi >= lights[k, L_COS]:
                    spot = max(cos_phi, 0.0) ** lights[k, L_EXP]
                else:
                    spot = 0.0
            c0, c1, c2 = s0 * f_att * spot, s1 * f_att * spot, s2 * f_att * spot
            ndl = nx * lx + ny * ly + nz * lz
            lam = max(ndl, 0.0)
            spec = 0.0
            if ndl > 0.0 and ks != 0.0:
                if blinn:
                    hx, hy, hz = lx + vx, ly + vy, lz + vz
                    hl = math.sqrt(hx * hx + hy * hy + hz * hz)
                    if hl > EPS:
                        spec = _power((nx * hx + ny * hy + nz * hz) / hl, shininess)
                else:
                    rx, ry, rz = 2.0 * nx * ndl - lx, 2.0 * ny * ndl - ly, 2.0 * nz * ndl - lz
                    spec = _power(rx * vx + ry * vy + rz * vz, shininess)
            r0 += _lit(c0 * lights[k, L_IP], kd, mats[m, M_OD], lam, ks, mats[m, M_OS], spec)
            r1 += _lit(c1 * lights[k, L_IP + 1], kd, mats[m, M_OD + 1], lam, ks,
                       mats[m, M_OS + 1], spec)
            r2 += _lit(c2 * lights[k, L_IP + 2], kd, mats[m, M_OD + 2], lam, ks,
                       mats[m, M_OS + 2], spec)
        out[i, 0], out[i, 1], out[i, 2] = r0, r1, r2

