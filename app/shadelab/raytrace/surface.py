"""What every CPU tracer does at a hit: the surface frame, the local model, shadow rays,
and the mirror and refracted directions with their weights (constant or Fresnel).

Shared by the Whitted tracer, the ray tree and the path tracer so that all three agree.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from shadelab.raytrace import rays as ray_kernels
from shadelab.raytrace import surface_rays
from shadelab.raytrace.accel import T_INF, Hits, SceneGeometry, build_accel, scene_geometry
from shadelab.raytrace.detail import SceneDetail
from shadelab.scene.model import Material, Scene
from shadelab.shading import kernels as shading_kernels
from shadelab.shading import packing
from shadelab.shading.reference import light_vectors, shade

MAX_SHADOW_CROSSINGS = 16  # transparent surfaces a shadow ray is followed through


@dataclass
class Surface:
    """N hit points, normals facing the side the ray came from.

    Attributes
    ----------
    position : (N, 3) float64, world space
    normal : (N, 3) float64, unit shading normal (interpolated corner normals)
    geo_normal : (N, 3) float64, unit geometric normal
    entering : (N,) bool, the ray hit the front (counter-clockwise) side
    obj : (N,) int64, object index
    hits : the Hits they come from (triangle, barycentrics: the texture lookups' uv)
    """

    position: np.ndarray
    normal: np.ndarray
    geo_normal: np.ndarray
    entering: np.ndarray
    obj: np.ndarray
    hits: Hits | None = None


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("ij,ij->i", a, b)


def _unit(v: np.ndarray) -> np.ndarray:
    length = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.maximum(length, 1e-300)


class Workspace:
    """Scratch arrays kept from one batch to the next, so the kernels write into memory that
    is already mapped (a fresh array of a few MB costs more in page faults than the loop that
    fills it). ``get(name, rows, cols, dtype)`` is a view of ``rows`` rows; the next ``get`` of
    the same name reuses it, so a caller keeps what it needs before asking again."""

    def __init__(self):
        self._arrays: dict[str, np.ndarray] = {}

    def get(self, name: str, rows: int, cols: int = 0, dtype=np.float64) -> np.ndarray:
        shape = (rows, cols) if cols else (rows,)
        have = self._arrays.get(name)
        if have is None or len(have) < rows or have.dtype != np.dtype(dtype):
            have = np.empty((max(rows, 1024),) + shape[1:], dtype)
            self._arrays[name] = have
        return have[:rows]

    def constant(self, name: str, rows: int, cols: int, value) -> np.ndarray:
        """A read-only view of ``rows`` rows filled with ``value`` (an int64 ramp 0, 1, ...
        for ``value="arange"``), filled again only when it grows."""
        have = self._arrays.get(name)
        if have is None or len(have) < rows:
            size = max(rows, 1024)
            have = (np.arange(size) if value == "arange"
                    else np.full((size, cols) if cols else (size,), value, np.float64))
            have.flags.writeable = False
            self._arrays[name] = have
        return have[:rows]


class TraceContext:
    """A scene prepared for CPU tracing: triangles, accelerator, materials, offset.

    Parameters
    ----------
    scene : the Scene (read once; rebuild the context after editing geometry)
    backend : "auto" (Embree where embreex imports), "embree" or "bvh"
    shadows : False makes every S_i = 1 (no shadow rays), as the raster without volumes
    offset : ray origin offset as a fraction of the scene diagonal (default: the preset's)
    local : "numba" (the kernels of :mod:`shadelab.shading.kernels`, fast) or "numpy" (calls
        :func:`shadelab.shading.reference.shade` itself); the two agree to 1e-9 (tested)
    """

    def __init__(self, scene: Scene, backend: str = "auto", shadows: bool = True,
                 offset: float | None = None, geometry: SceneGeometry | None = None,
                 local: str = "numba"):
        if local not in ("numba", "numpy"):
            raise ValueError(f"unknown local model implementation {local!r}")
        self.scene = scene
        self.kernels = local == "numba"
        self.geometry = scene_geometry(scene) if geometry is None else geometry
        self.accel = build_accel(self.geometry, backend)
        self.lights = scene.active_lights()
        self.shadows = shadows
        names = sorted({obj.material for obj in scene.objects})
        self.material_names = names
        self.materials: list[Material] = [scene.materials[name] for name in names]
        self.object_material = np.array([names.index(o.material) for o in scene.objects],
                                        dtype=np.int64)
        self.detail = SceneDetail(self)  # textured materials: Od(u, v), bumped normals
        fraction = scene.raytrace.offset if offset is None else offset
        self.eps = float(fraction) * self.geometry.diagonal  # world units
        self.background = np.asarray(scene.render.background, dtype=np.float64)
        self.specular = scene.render.specular
        self.shadow_rays = 0  # counter, for rays/s figures
        self.workspace = Workspace()  # the Whitted kernels' scratch (one batch at a time)
        self.material_table = packing.material_table(self.materials)
        self.light_table = packing.light_table(self.lights)
        self.Ia = np.asarray(scene.Ia, dtype=np.float64)
        mats = self.materials
        self.kr = np.array([m.mirror for m in mats], dtype=np.float64)
        self.kt = np.array([m.kt for m in mats], dtype=np.float64)
        self.ior = np.array([m.ior for m in mats], dtype=np.float64)
        self.tint = np.array([m.Ot if m.transparency == "filtered" else (1.0, 1.0, 1.0)
                              for m in mats], dtype=np.float64).reshape(-1, 3)

    # ------------------------------------------------------------ hits
    def surface(self, origins: np.ndarray, dirs: np.ndarray, hits: Hits) -> Surface:
        """The surface at each hit (call with hits that all hit something)."""
        g = self.geometry
        tri = hits.tri
        if self.kernels:
            return Surface(*surface_rays.surface_frame(
                np.ascontiguousarray(origins), np.ascontiguousarray(dirs), hits.t, tri,
                hits.u, hits.v, g.corner_normals, g.face_normals, g.object_index), hits=hits)
        position = origins + hits.t[:, None] * dirs
        w0 = 1.0 - hits.u - hits.v
        corner = g.corner_normals[tri]
        normal = _unit(w0[:, None] * corner[:, 0] + hits.u[:, None] * corner[:, 1]
                       + hits.v[:, None] * corner[:, 2])
        geo = g.face_normals[tri]
        # Back faces: flip both normals when the geometric face is seen from behind
        entering = _dot(geo, dirs) < 0.0
        sign = np.where(entering, 1.0, -1.0)[:, None]
        return Surface(position, normal * sign, geo * sign, entering, g.object_index[tri],
                       hits=hits)

    def material_ids(self, surf: Surface) -> np.ndarray:
        return self.object_material[surf.obj]

    # ------------------------------------------------------------ local model
    def shadow_factors(self, surf: Surface, select: np.ndarray | None = None) -> list[np.ndarray]:
        """S_i per light for the points ``select`` (all by default): 1 lit, 0 in shadow.

        Each S_i is (N,) when no shadow caster is transparent (the opaque scenes' arrays,
        bit for bit), else (N, 3): the kt-filtered transmittance of
        :meth:`shadow_transmittance` where an occlusion query finds a blocker."""
        pos = surf.position if select is None else surf.position[select]
        ng = surf.geo_normal if select is None else surf.geo_normal[select]
        if self.kernels:
            return self._shadow_factors_kernel(np.ascontiguousarray(pos),
                                               np.ascontiguousarray(ng))
        factors = []
        for light in self.lights:
            to_light, distance = light_vectors(light, pos)
            to_light = np.ascontiguousarray(to_light)
            if not self.shadows:
                factors.append(np.ones(len(pos)))
                continue
            facing = _dot(ng, to_light) > 0.0
            s = np.zeros(len(pos))
            idx = np.flatnonzero(facing)
            if len(idx):
                origin = pos[idx] + self.eps * ng[idx]
                tmax = np.where(np.isfinite(distance[idx]), distance[idx] - self.eps, T_INF)
                blocked = self.shadow_occluded(origin, to_light[idx], tmax)
                s[idx] = np.where(blocked, 0.0, 1.0)
                self.shadow_rays += len(idx)
                s = self._filter_blocked(s, idx, blocked, origin, to_light[idx], tmax)
            factors.append(s)
        return factors

    def _shadow_factors_kernel(self, pos: np.ndarray, ng: np.ndarray) -> list[np.ndarray]:
        factors = []
        for k in range(len(self.lights)):
            if not self.shadows:
                factors.append(np.ones(len(pos)))
                continue
            origin, dirs, tmax, facing = surface_rays.shadow_rays(pos, ng, self.light_table, k,
                                                             self.eps, T_INF)
            s = np.zeros(len(pos))
            idx = np.flatnonzero(facing)
            if len(idx):
                blocked = self.shadow_occluded(origin[idx], dirs[idx], tmax[idx])
                s[idx] = np.where(blocked, 0.0, 1.0)
                self.shadow_rays += len(idx)
                s = self._filter_blocked(s, idx, blocked, origin[idx], dirs[idx], tmax[idx])
            factors.append(s)
        return factors

    # ------------------------------------------------------------ kt-filtered shadows
    @cached_property
    def transparent_casters(self) -> bool:
        """Does any shadow caster have kt > 0? Only then are shadow rays followed through
        blockers (kt-filtered S_i); every other scene keeps its binary S_i, bit for bit."""
        g = self.geometry
        faces = g.object_index[g.casts_shadow]
        return bool(len(faces)) and bool(np.any(self.kt[self.object_material[faces]] > 0.0))

    @cached_property
    def _light_takers(self):
        """The shadow casters that take light away: opaque ones and those whose kt Ot (kt for
        the interpolated model) is below 1 in some channel. A caster that passes every
        channel whole (clear glass: kt = 1, Ot = 1) changes no shadow ray (each crossing
        multiplies by 1.0 exactly), so a ray only it blocks is lit, S_i = 1, without being
        followed through it. ``None`` when every caster takes light (the accelerator's
        caster scene answers)."""
        g = self.geometry
        if not self.transparent_casters:
            return None
        clear = g.casts_shadow & np.all(
            self._shadow_filter[self.object_material[g.object_index]] >= 1.0, axis=1)
        if not clear.any():
            return None
        return self.accel.occluder(np.flatnonzero(g.casts_shadow & ~clear))

    def shadow_occluded(self, origins: np.ndarray, dirs: np.ndarray,
                        tmax: np.ndarray) -> np.ndarray:
        """The shadow rays' first question: is a caster that takes light away in the way?
        (Where one is, :meth:`shadow_transmittance` follows the ray.)"""
        takers = self._light_takers
        if takers is None:
            return self.accel.occluded(origins, dirs, tmax)
        return takers.occluded(origins, dirs, tmax)

    def shadow_transmittance(self, origins: np.ndarray, dirs: np.ndarray,
                             tmax: np.ndarray) -> np.ndarray:
        """(M, 3) transmittance of M shadow rays: the product of kt Ot (kt alone for the
        "interpolated" model, whose Ot is taken as 1) over every shadow-casting surface the
        ray crosses before ``tmax``; 0 at the first opaque caster (kt = 0).

        Each crossing is a surface: a closed transparent solid (a glass sphere) filters at
        entry and at exit, a single quad pane once. Objects with ``cast_shadows = false``
        are passed through with factor 1. The ray restarts eps past each hit; after
        ``MAX_SHADOW_CROSSINGS`` crossings an occlusion query decides (blocked: 0).
        """
        g = self.geometry
        m = len(origins)
        trans = np.ones((m, 3))
        if g.count == 0:
            return trans
        o = np.array(origins, dtype=np.float64).reshape(m, 3)
        d = np.ascontiguousarray(dirs, dtype=np.float64).reshape(m, 3)
        left = np.array(np.broadcast_to(tmax, (m,)), dtype=np.float64)
        active = np.arange(m)
        ws = self.workspace
        # Each crossing: one closest-hit query of the rays still carrying light, and one
        # kernel (hits.transmit_step) for the filter and the restart, in place
        for _ in range(MAX_SHADOW_CROSSINGS):
            k = len(active)
            if k == 0:
                return trans
            og, dg, lg = ws.get("tr_o", k, 3), ws.get("tr_d", k, 3), ws.get("tr_left", k)
            surface_rays.gather_rays(active, o, d, left, og, dg, lg)
            t, tri, _, _ = self.accel.intersect_raw(og, dg, lg)
            self.shadow_rays += k
            following = ws.get("tr_active", k, 0, np.int64)
            count = surface_rays.transmit_step(active, t, tri, trans, o, d, left, g.casts_shadow,
                                          g.object_index, self.object_material,
                                          self._shadow_filter, self.eps, following)
            active = following[:count].copy()
        if len(active):
            blocked = self.accel.occluded(o[active], d[active], left[active])
            self.shadow_rays += len(active)
            trans[active[blocked]] = 0.0
        return trans

    @cached_property
    def _shadow_filter(self) -> np.ndarray:
        """(materials, 3) kt Ot per material (0 for the opaque ones)."""
        return np.ascontiguousarray(self.kt[:, None] * self.tint)

    def _filter_blocked(self, s: np.ndarray, idx: np.ndarray, blocked: np.ndarray,
                        origins: np.ndarray, dirs: np.ndarray, tmax: np.ndarray) -> np.ndarray:
        """S_i (N,) unchanged without transparent casters, else (N, 3) with the blocked rays'
        (``idx[blocked]``) transmittance in place of their 0."""
        if not self.transparent_casters:
            return s
        s3 = np.repeat(s[:, None], 3, axis=1)
        rows = np.flatnonzero(blocked)
        if len(rows):
            s3[idx[rows]] = self.shadow_transmittance(origins[rows], dirs[rows], tmax[rows])
        return s3

    def filtered_shadow_matrix(self, shape: tuple[int, int], light: np.ndarray,
                               point: np.ndarray, blocked: np.ndarray, origins: np.ndarray,
                               dirs: np.ndarray, tmax: np.ndarray) -> np.ndarray:
        """The Whitted kernels' S (L, N, 3) for ``shape`` (L, N) from their shadow rays j (to
        light ``light[j]`` from point ``point[j]``): 1 where unblocked, the ray's
        :meth:`shadow_transmittance` where blocked, 0 for the pairs with no ray (facing away).
        The array is the workspace's, valid until the next call."""
        rows = np.flatnonzero(blocked)
        trans = (self.shadow_transmittance(origins[rows], dirs[rows], tmax[rows]) if len(rows)
                 else np.zeros((0, 3)))
        n_lights, n = shape
        s = self.workspace.get("shadow3", n_lights * n * 3).reshape(n_lights, n, 3)
        surface_rays.shadow_matrix3(s, light, point, np.ascontiguousarray(blocked, dtype=np.bool_),
                               trans)
        return s

    def local_per_channel(self, shade_one, shadow3: np.ndarray, out: np.ndarray) -> np.ndarray:
        """The lecture's equation with a per-channel S_i: channel c of ``out`` is channel c
        of ``shade_one(S[..., c])`` (every channel of I uses only its own S_i,c, so this is
        I_c = Le_c + Ia_c ka Od_c + sum_i S_i,c f_att Ip_i,c [kd Od_c N.L + ks Os_c (R.V)^n])."""
        for c in range(3):
            out[:, c] = shade_one(np.ascontiguousarray(shadow3[..., c]))[:, c]
        return out

    def local(self, surf: Surface, dirs: np.ndarray, shadow: list | None = None) -> np.ndarray:
        """The lecture's local model at each hit (reference.shade, with shadow-ray S_i)."""
        out = np.zeros((len(surf.position), 3))
        if len(out) == 0:
            return out
        shadow = self.shadow_factors(surf) if shadow is None else shadow
        if shadow and np.ndim(shadow[0]) == 2:  # kt-filtered S_i (N, 3): a pass per channel
            return self.local_per_channel(lambda s: self.local(surf, dirs, list(s)),
                                          np.stack(shadow), out)
        mat = self.material_ids(surf)
        if self.kernels:
            s = (np.stack(shadow) if shadow else np.zeros((0, len(out))))
            out = shading_kernels.local_shade(surf.position, surf.normal,
                                      np.ascontiguousarray(-dirs), mat, self.material_table,
                                      self.light_table, self.Ia, self.specular == "blinn",
                                      np.ascontiguousarray(s, dtype=np.float64))
        else:
            for m in np.unique(mat):
                idx = np.flatnonzero(mat == m)
                pos = surf.position[idx]
                out[idx] = shade(pos, surf.normal[idx], pos - dirs[idx], self.materials[m],
                                 self.lights, self.scene.Ia, self.specular,
                                 [s[idx] for s in shadow])
        if self.detail.active and surf.hits is not None:
            h = surf.hits
            self.detail.reshade(out, surf.position, surf.normal, dirs, mat, h.tri, h.u, h.v,
                                shadow)
        return out

    # ------------------------------------------------------------ secondary rays
    def secondary(self, surf: Surface, dirs: np.ndarray, fresnel: bool):
        """Mirror and refracted rays: (refl_dir, refl_w, refr_dir, refr_w), weights (N, 3).

        Without Fresnel: reflection kr (``Material.mirror``), refraction kt (times Ot for
        the filtered transparency model); total internal reflection sends kt to reflection.
        With Fresnel: the dielectric reflectance F splits kt into kt F (added to kr) and
        kt (1 - F); a mirror coating kr stays constant.
        """
        n = len(dirs)
        mat = self.material_ids(surf)
        kr, kt, ior, tint = self.kr[mat], self.kt[mat], self.ior[mat], self.tint[mat]
        refl_dir, refr_dir, tir, f = reflect_refract(dirs, self.spawn_normals(surf, dirs, mat),
                                                     surf.entering, ior)
        if fresnel:
            refl_scalar = kr + kt * f
            refr_scalar = kt * (1.0 - f)
        else:
            refl_scalar = kr + np.where(tir, kt, 0.0)
            refr_scalar = np.where(tir, 0.0, kt)
        refl_w = np.repeat(refl_scalar[:, None], 3, axis=1)
        refr_w = refr_scalar[:, None] * tint
        return refl_dir, refl_w.reshape(n, 3), refr_dir, refr_w.reshape(n, 3)

    def spawn(self, surf: Surface, dirs: np.ndarray, weight: np.ndarray, pixel: np.ndarray,
              fresnel: bool, min_weight: float):
        """The next generation of rays (origins, dirs, weights, pixels) above ``min_weight``."""
        mat = self.material_ids(surf)
        if self.kernels:
            return ray_kernels.spawn_secondary(surf.position, self.spawn_normals(surf, dirs, mat),
                                           surf.geo_normal,
                                           surf.entering, np.ascontiguousarray(dirs), mat,
                                           weight, pixel, self.kr, self.kt, self.ior,
                                           self.tint, fresnel, min_weight, self.eps)
        refl_dir, refl_w, refr_dir, refr_w = self.secondary(surf, dirs, fresnel)
        refl_w, refr_w = weight * refl_w, weight * refr_w
        keep_r = np.flatnonzero(refl_w.max(axis=1) >= max(min_weight, 1e-12))
        keep_t = np.flatnonzero(refr_w.max(axis=1) >= max(min_weight, 1e-12))
        origins = np.concatenate([self.offset_origin(surf, keep_r, True),
                                  self.offset_origin(surf, keep_t, False)])
        return (origins, np.concatenate([refl_dir[keep_r], refr_dir[keep_t]]),
                np.concatenate([refl_w[keep_r], refr_w[keep_t]]),
                np.concatenate([pixel[keep_r], pixel[keep_t]]))

    def spawn_normals(self, surf: Surface, dirs: np.ndarray, mat: np.ndarray) -> np.ndarray:
        """Shading normals for the mirror and refracted directions: bumped where the
        material has a bump map (:meth:`SceneDetail.bumped`), else ``surf.normal``."""
        if not self.detail.active or surf.hits is None:
            return surf.normal
        h = surf.hits
        return self.detail.bumped(surf.normal, np.asarray(dirs, dtype=np.float64), mat, h.tri,
                                  h.u, h.v)

    def offset_origin(self, surf: Surface, idx: np.ndarray, outward: bool) -> np.ndarray:
        """Origins moved off the surface by eps, to the incoming side (or through it)."""
        sign = self.eps if outward else -self.eps
        return surf.position[idx] + sign * surf.geo_normal[idx]


def reflect_refract(dirs: np.ndarray, normal: np.ndarray, entering: np.ndarray,
                    ior: np.ndarray):
    """Mirror and Snell directions, total internal reflection and Fresnel reflectance.

    Parameters
    ----------
    dirs : (N, 3) unit incident directions (travelling toward the surface)
    normal : (N, 3) unit normals facing the incident side
    entering : (N,) bool, going from outside (index 1) into the material (index ``ior``)
    ior : (N,) the material's index of refraction

    Notes
    -----
    R = D - 2 (D . N) N;  eta = n1 / n2;  cos_t^2 = 1 - eta^2 (1 - cos_i^2) (< 0: TIR);
    T = eta D + (eta cos_i - cos_t) N;  F = (r_s^2 + r_p^2) / 2 with
    r_s = (n1 cos_i - n2 cos_t) / (n1 cos_i + n2 cos_t), r_p = (n2 cos_i - n1 cos_t) / (...).
    """
    cos_i = np.clip(-_dot(dirs, normal), 0.0, 1.0)
    refl = dirs + 2.0 * cos_i[:, None] * normal
    n1 = np.where(entering, 1.0, ior)
    n2 = np.where(entering, ior, 1.0)
    eta = n1 / n2
    k = 1.0 - eta * eta * (1.0 - cos_i * cos_i)
    tir = k < 0.0
    cos_t = np.sqrt(np.maximum(k, 0.0))
    refr = eta[:, None] * dirs + (eta * cos_i - cos_t)[:, None] * normal
    refr = _unit(refr)
    rs = (n1 * cos_i - n2 * cos_t) / np.maximum(n1 * cos_i + n2 * cos_t, 1e-300)
    rp = (n2 * cos_i - n1 * cos_t) / np.maximum(n2 * cos_i + n1 * cos_t, 1e-300)
    f = np.where(tir, 1.0, 0.5 * (rs * rs + rp * rp))
    return _unit(refl), refr, tir, f
