"""numba mirrors of the per-hit work, for speed: the surface frame at hits, shadow-ray setup,
the lecture's local model, the spawning of Whitted's secondary rays and one path-tracer
vertex (emission with MIS, next-event set-up, lobe choice, Russian roulette).

:func:`local_shade` mirrors :func:`shadelab.shading.reference.shade` term by term (same guards:
EPS = 1e-12, pow only where the cosine is positive, f_att = 1 at infinite distance);
``tests/raytrace/test_raytrace_kernels.py`` holds the two together on random inputs. The tracers use
these kernels by default and the numpy reference with ``TraceContext(local="numpy")``.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from shadelab.constants import SHADING_EPS as EPS
from shadelab.scene.model import Light, Material
from shadelab.shading.codes import ATTENUATION_CODES, LIGHT_KIND_CODES
from shadelab.shading.lights import pack_lights

# The codes as the light table stores them (float64); numba freezes them at compile time
_DIRECTIONAL = float(LIGHT_KIND_CODES["directional"])
_SPOT = float(LIGHT_KIND_CODES["spot"])
_ATT_NONE = float(ATTENUATION_CODES["none"])
_ATT_INVERSE_SQUARE = float(ATTENUATION_CODES["inverse_square"])

# Material table columns
M_KA, M_KD, M_KS, M_N, M_OD, M_OS, M_LE = 0, 1, 2, 3, 4, 7, 10
MATERIAL_COLUMNS = 13
# Light table columns
L_KIND, L_POS, L_DIR, L_IP = 0, 1, 4, 7
L_ATT, L_C1, L_C2, L_C3, L_COS, L_EXP = 10, 11, 12, 13, 14, 15
LIGHT_COLUMNS = 16


def material_table(materials: list[Material]) -> np.ndarray:
    """(M, 13) float64: ka, kd, ks, n, Od, Os, emission."""
    table = np.zeros((max(len(materials), 1), MATERIAL_COLUMNS))
    for i, m in enumerate(materials):
        table[i, :4] = (m.ka, m.kd, m.ks, m.n)
        table[i, M_OD:M_OD + 3] = m.Od
        table[i, M_OS:M_OS + 3] = m.Os
        table[i, M_LE:M_LE + 3] = m.emission
    return table


def light_table(lights: list[Light]) -> np.ndarray:
    """(L, 16) float64: kind, position, unit direction, Ip, attenuation, c1-c3, cos cone, e
    (from :func:`shadelab.shading.lights.pack_lights`, as the GL uniforms are)."""
    packed = pack_lights(lights)
    table = np.zeros((len(lights), LIGHT_COLUMNS))
    table[:, L_KIND] = packed.kind
    table[:, L_POS:L_POS + 3] = packed.position
    table[:, L_DIR:L_DIR + 3] = packed.direction
    table[:, L_IP:L_IP + 3] = packed.Ip
    table[:, L_ATT] = packed.attenuation
    table[:, L_C1:L_C3 + 1] = packed.c
    table[:, L_COS] = packed.spot[:, 0]
    table[:, L_EXP] = packed.spot[:, 1]
    return table


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


@nb.njit(cache=True)
def add_misses(out, pixel, weight, tri, background):
    """out[pixel[i]] += weight[i] * background where the ray missed (``tri`` < 0)."""
    for i in range(len(pixel)):
        if tri[i] < 0:
            for c in range(3):
                out[pixel[i], c] += weight[i, c] * background[c]


# ---------------------------------------------------------------------- scattering helpers
# pbrt-v4's names: Reflect, FrDielectric, Refract, SampleCosineHemisphere. Inlined, so the
# callers compile to what they were when these lines were written out in each of them.
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


# ---------------------------------------------------------------------- one path vertex
@nb.njit(cache=True, inline="always")
def _emission_weight(bsdf_pdf, t, cos_y, em_area):
    """MIS weight (balance heuristic) of emission reached by a BSDF sample, against area
    sampling of the emitters; 1 after a specular bounce (pdf 0)."""
    if not bsdf_pdf > 0.0:
        return 1.0
    light_pdf = t * t / max(cos_y * em_area, 1e-300)
    return bsdf_pdf / (bsdf_pdf + light_pdf)


@nb.njit(cache=True)
def _next_event(i, m, emitters, rho, beta, px, py, pz, nx, ny, nz, gx, gy, gz, prob_d, eps,
                rnd, nee_o, nee_d, nee_t, nee_ok, nee_val):
    """Next-event estimation: a shadow ray to one point on the emitters, chosen by area."""
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


@nb.njit(cache=True)
def path_vertex(out, pixel, beta, bsdf_pdf, position, normal, geo, entering, dirs, t, mat,
                surfaces, emitters, eps, rnd, roulette):
    """One path vertex per path: emission (MIS-weighted), next-event set-up, lobe choice.

    Mirrors ``PathTracer`` (see :mod:`shadelab.raytrace.pathtrace` for the estimator).
    ``surfaces`` = (rho, kr, kt, ior, emission) per material; ``emitters`` = (cdf, p0, e1, e2,
    normal, le, total area) of the emitting triangles. ``rnd`` holds 7 uniforms per path:
    emitter, 2 barycentrics, lobe, 2 direction, roulette.
    Returns the shadow rays of next-event estimation (origins, dirs, tmax, candidate flag,
    unoccluded contribution) and the continued paths (origins, dirs, beta, pdf, alive).
    """
    rho, kr, kt, ior, emission = surfaces
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
        # Emission, MIS-weighted after a diffuse bounce
        if max(emission[m, 0], max(emission[m, 1], emission[m, 2])) > 0.0:
            w = _emission_weight(bsdf_pdf[i], t[i], abs(gx * dx + gy * dy + gz * dz), em_area)
            for c in range(3):
                out[pixel[i], c] += beta[i, c] * emission[m, c] * w
        p_d = (rho[m, 0] + rho[m, 1] + rho[m, 2]) / 3.0
        total = p_d + kr[m] + kt[m]
        prob_d = p_d / total if total > 0.0 else 0.0
        # Next-event estimation: one point on the emitters, by area
        if n_em > 0 and p_d > 0.0:
            _next_event(i, m, emitters, rho, beta, px, py, pz, nx, ny, nz, gx, gy, gz, prob_d,
                        eps, rnd, nee_o, nee_d, nee_t, nee_ok, nee_val)
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
        else:
            ox, oy, oz, side, weight, prob = _specular_lobe(u, p_d, kr[m], kt[m], ior[m],
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
