"""A reference Monte Carlo path tracer for the rendering equation (the lecture's last slide).

    L(x, w) = Le(x) + integral over the hemisphere of f(x) L(x', -w') cos(theta') dw'

Units follow ARCHITECTURE.md section 2: radiance throughout, a diffuse BRDF f = rho / pi with
rho = kd * Od, and a material's ``emission`` is its radiance Le (two-sided, as the raster
shows it). The lecture's point, spot and directional lights light the scene too, as delta
lights sampled at every path vertex: their direct term is exactly the lecture's
S_i f_att Ip [kd Od (N.L) + ks Os (R.V)^n] (no ambient term: the paths carry the indirect
light the ambient term stood for), i.e. a lecture light of intensity Ip is a point source of
radiant intensity pi Ip for the diffuse BRDF rho / pi, so a path tracer's first bounce equals
the raster and Whitted images and everything after it is global illumination. A light marked
``stand_in`` (the Cornell box's point light for its ceiling quad) is skipped: the emitting
surface it stands for lights the paths. Ideal mirrors (``Material.mirror``) and glass
(``kt``, Fresnel reflection or Snell refraction) are delta lobes. The ks highlight is also a
sampled glossy lobe: the BRDF f_s = ks Os lobe / (pi cos theta_i), lobe = (R.wi)^n or
(N.H)^n after ``render.specular``, the one whose delta-light term is exactly the lecture's
ks Os (R.V)^n (:mod:`shadelab.raytrace.glossy`: its normalization, albedo and pdfs), so
the area light's highlight and glossy inter-reflection come from the same BRDF as the delta
lights' highlight. With ``kr`` unset (``Material.mirror`` = ks, the ray tracer's reading of
the lecture) a material keeps its mirror lobe beside the glossy one; ``kr = 0`` makes it
glossy only.

Estimator (per path vertex, all paths of a bounce as one numpy batch, rays cast by Embree):

- next-event estimation: one emitter point sampled by area over all emitting triangles
  (pdf d^2 / (cos_y A_total) in solid angle), when visible;
- a lobe picked with probability proportional to mean(rho), the glossy lobe's albedo at
  normal incidence (:func:`shadelab.raytrace.glossy.lobe_weight`), kr and kt; the diffuse
  lobe samples cos-weighted directions (weight rho / P), the glossy lobe cos^n about R (or
  the half vector about N) (weight ks Os (f_s cos / pdf) / P);
- multiple importance sampling (balance heuristic) between the two, lobe by lobe: the
  diffuse and glossy parts of next-event estimation each against their own lobe's pdf
  (times P), and emitters reached after a diffuse or glossy bounce; after a mirror or glass
  bounce (and from the camera) Le counts in full. MIS tames the 1/d^2 spikes of light
  sampling in corners, where plain NEE's heavy-tailed estimates make finite-sample means run
  low;
- Russian roulette from the fifth vertex, survival min(max(beta), 0.95);
- a ray that leaves the scene sees ``render.background`` as a constant environment
  radiance (not light-sampled; black in the Cornell presets).

Emitters are two-sided (a closed furnace box converges to Le / (1 - rho) seen from inside).

Samples: by default (``raytrace.sampler = "sobol"``) every 2-D decision of a path (pixel
jitter, emitter point, BSDF direction, lobe choice and roulette) draws Owen-scrambled
Sobol' points per pixel (:mod:`shadelab.raytrace.sampler`), so each pixel's samples are
stratified in each pair; ``"independent"`` draws uniforms from each tile's generator.

Execution: with Sobol' samples, Embree and neither delta lights nor textures, whole paths run
in one parallel numba call per tile (:mod:`shadelab.raytrace.fused`, Embree called ray by
ray), the image the bounce-by-bounce wavefront below traces bit for bit; the wavefront does
the rest (and ``FUSED = False`` forces it).
"""

from __future__ import annotations

import time
from typing import Iterator

import numba
import numpy as np

from shadelab.constants import SHADING_EPS as EPS
from shadelab.constants import T_INF
from shadelab.errors import ShadeLabError
from shadelab.progress import Progress
from shadelab.raytrace import embree_direct, fused, glossy, surface_rays, vertex
from shadelab.raytrace import rays as ray_kernels
from shadelab.raytrace.accel import Hits, embree_available
from shadelab.raytrace.sampler import SAMPLERS, SobolSampler
from shadelab.raytrace.surface import TraceContext, reflect_refract
from shadelab.raytrace.whitted import stratified_jitter
from shadelab.scene.model import Scene
from shadelab.shading import kernels as shading_kernels
from shadelab.shading import packing

TILE_PATHS = 16384    # paths per work unit (one chunk of the generator)
FUSED_TILE_PATHS = 1 << 18  # the same where whole paths run in one call (raytrace/fused.py):
                            # a 1280 x 800 sample pass in 4 Progress steps, not 63
WAVEFRONT_PATHS = 65536  # an image smaller than a tile: sample passes per wavefront up to
                         # this many paths (CPU per sample at 64 x 64 on 2 loaded cores:
                         # 1 pass 340 k samples/s, 4: 420 k, 16: 450 k, 64: 435 k)
MAX_BOUNCES = 64      # hard cap; Russian roulette ends paths long before
RR_START = 4          # bounces before Russian roulette starts (3 cost 6 % more time at
                      # equal error on cornell: variance x CPU 0.85 against 0.80)
FUSED = True          # trace whole paths in one numba loop where the scene allows
                      # (PathTracer.fused; False keeps every render on the wavefront)


def check_lit(scene: Scene, label: str) -> None:
    """Refuse a scene with nothing to light its paths: no emitting object and no light that
    is on and not a ``stand_in``."""
    emitters = [o for o in scene.objects if max(scene.materials[o.material].emission) > 0.0]
    lights = [light for light in scene.active_lights() if not light.stand_in]
    if not emitters and not lights:
        raise ShadeLabError(f"{label}: the path tracer needs an emitter (a material with "
                            "emission > 0 on some object) or a light that is not a stand_in")


class Emitters:
    """Emitting triangles, sampled by area."""

    def __init__(self, ctx: TraceContext, emission: np.ndarray):
        g = ctx.geometry
        le = emission[ctx.object_material[g.object_index]] if g.count else np.zeros((0, 3))
        self.index = np.flatnonzero(le.max(axis=1) > 0.0) if g.count else np.zeros(0, int)
        tri = g.triangles[self.index]
        self.p0 = np.ascontiguousarray(tri[:, 0])
        self.e1 = np.ascontiguousarray(tri[:, 1] - tri[:, 0])
        self.e2 = np.ascontiguousarray(tri[:, 2] - tri[:, 0])
        self.normal = np.ascontiguousarray(g.face_normals[self.index])
        self.le = np.ascontiguousarray(le[self.index])
        areas = 0.5 * np.linalg.norm(np.cross(self.e1, self.e2), axis=1)
        self.total_area = float(areas.sum())
        self.cdf = np.cumsum(areas) / max(self.total_area, 1e-300)

    @property
    def count(self) -> int:
        return len(self.index)

    def sample(self, rng: np.random.Generator, n: int):
        """n points uniform by area: (points, normals, Le), each (n, 3)."""
        k = np.minimum(np.searchsorted(self.cdf, rng.random(n), side="right"), self.count - 1)
        r1, r2 = rng.random(n), rng.random(n)
        s = np.sqrt(r1)
        a, b = s * (1.0 - r2), s * r2  # uniform barycentrics
        points = self.p0[k] + a[:, None] * self.e1[k] + b[:, None] * self.e2[k]
        return points, self.normal[k], self.le[k]


def _basis(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit tangents completing n to an orthonormal frame (Duff et al. 2017)."""
    sign = np.where(n[:, 2] >= 0.0, 1.0, -1.0)
    a = -1.0 / (sign + n[:, 2])
    b = n[:, 0] * n[:, 1] * a
    t = np.stack([1.0 + sign * n[:, 0] ** 2 * a, sign * b, -sign * n[:, 0]], axis=1)
    bt = np.stack([b, sign + n[:, 1] ** 2 * a, -n[:, 1]], axis=1)
    return t, bt


def _directions_about(axis: np.ndarray, r1: np.ndarray, r2: np.ndarray) -> np.ndarray:
    """Unit directions about unit axes (N, 3) at cos(theta) = sqrt(1 - r1), phi = 2 pi r2:
    cosine-weighted for uniform r1 (pass 1 - cos^2 for another polar angle)."""
    r = np.sqrt(r1)
    phi = 2.0 * np.pi * r2
    x, y, z = r * np.cos(phi), r * np.sin(phi), np.sqrt(np.maximum(1.0 - r1, 0.0))
    t, bt = _basis(axis)
    return x[:, None] * t + y[:, None] * bt + z[:, None] * axis


def cosine_directions(n: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Unit directions about unit normals n (N, 3), pdf cos(theta) / pi."""
    m = len(n)
    r1, r2 = rng.random(m), rng.random(m)
    return _directions_about(n, r1, r2)


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("ij,ij->i", a, b)


def glossy_lobe_pdf(wi: np.ndarray, n: np.ndarray, v: np.ndarray, shininess: np.ndarray,
                    blinn: bool) -> tuple[np.ndarray, np.ndarray]:
    """lobe(wi) ((R.wi)^n or (N.H)^n, the direct term's guards) and the glossy lobe's pdf of
    wi (solid angle), for unit wi, n, v (N, 3): numpy twin of :func:`glossy.lobe_pdf`."""
    if blinn:
        h = wi + v
        hl = np.linalg.norm(h, axis=1)
        ok = hl > EPS
        h = h / np.where(ok, hl, 1.0)[:, None]
        c, vh = np.where(ok, _dot(n, h), 0.0), _dot(v, h)
        ok &= vh > 0.0
        scale = np.where(ok, 1.0 / (4.0 * np.where(ok, vh, 1.0)), 0.0)
    else:
        c, scale = _dot(2.0 * _dot(n, v)[:, None] * n - v, wi), 1.0
    lobe = np.where(c > 0.0, np.maximum(c, EPS) ** shininess, 0.0)
    return lobe, (shininess + 1.0) / (2.0 * np.pi) * lobe * scale


def glossy_directions(n: np.ndarray, v: np.ndarray, shininess: np.ndarray, blinn: bool,
                      u1: np.ndarray, u2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Directions from the glossy lobe and their f_s cos / pdf per unit ks Os (0: V.H <= 0):
    numpy twin of :func:`glossy.sample_lobe`."""
    cos_a = u1 ** (1.0 / (shininess + 1.0))
    u_disk = 1.0 - cos_a * cos_a
    if blinn:
        h = _directions_about(n, u_disk, u2)
        vh = _dot(v, h)
        return 2.0 * vh[:, None] * h - v, 8.0 * np.maximum(vh, 0.0) / (shininess + 1.0)
    axis = 2.0 * _dot(n, v)[:, None] * n - v
    return _directions_about(axis, u_disk, u2), 2.0 / (shininess + 1.0)


class PathTracer:
    """The scene prepared once; :meth:`radiance` traces a batch of camera paths."""

    def __init__(self, scene: Scene, backend: str = "auto", ctx: TraceContext | None = None,
                 local: str = "numba"):
        self.ctx = TraceContext(scene, backend, local=local) if ctx is None else ctx
        mats = self.ctx.materials
        self.kd = np.array([m.kd for m in mats], float)
        self.rho = np.array([packing.reflectance(m) for m in mats], float).reshape(-1, 3)
        self.kr = np.array([m.mirror for m in mats], float)
        self.kt = np.array([m.kt for m in mats], float)
        self.ior = np.array([m.ior for m in mats], float)
        self.emission = np.array([m.emission for m in mats], float).reshape(-1, 3)
        # The glossy lobe (shadelab.raytrace.glossy): ks Os, n, and its lobe-choice weight
        self.blinn = self.ctx.specular == "blinn"
        self.ks_os = np.array([np.multiply(m.ks, m.Os) for m in mats], float).reshape(-1, 3)
        self.shininess = np.array([m.n for m in mats], float)
        self.p_glossy = glossy.lobe_weight(self.ks_os.mean(axis=1), self.shininess, self.blinn)
        self.emitters = Emitters(self.ctx, self.emission)
        # The lecture's delta lights (all but stand-ins), with a material table without the
        # ambient and emission terms: those are counted by the paths themselves.
        self.delta_lights = [light for light in self.ctx.lights if not light.stand_in]
        self.delta_table = packing.light_table(self.delta_lights)
        self.direct_materials = self.ctx.material_table.copy()
        self.direct_materials[:, packing.M_LE:packing.M_LE + 3] = 0.0
        self.rays = 0  # counter of rays cast (paths and shadow rays)
        self.primary_hits = 0  # counter of camera rays that hit something
        self._fused_scene = None
        self._fused_tried = False
        self._hit_rows = np.zeros(0, bool)  # the last batch's camera rays that hit

    def fused_scene(self) -> embree_direct.EmbreeScene | None:
        """The Embree scene :func:`shadelab.raytrace.fused.trace_tile` traces whole paths
        in, or None where the wavefront must: the numpy implementation, another accelerator
        than Embree, the lecture's delta lights, textures or bumps, ``FUSED`` off, or no
        Embree library to open (:mod:`shadelab.raytrace.embree_direct`)."""
        if not self._fused_tried:
            self._fused_tried = True
            ctx = self.ctx
            if (FUSED and ctx.kernels and ctx.accel.name == "embree" and not self.delta_lights
                    and not ctx.detail.active):
                self._fused_scene = embree_direct.embree_scene(ctx.geometry.triangles)
        return self._fused_scene if FUSED else None

    def trace_tile(self, camera, size: tuple[int, int], r0: int, r1: int, first: int,
                   passes: int, seed: int) -> np.ndarray:
        """Rows r0..r1 of Sobol' sample passes first .. first + passes - 1 in one numba
        call (:func:`shadelab.raytrace.fused.trace_tile`; call where :meth:`fused_scene` is
        not None): radiance summed over the passes ((r1 - r0) width, 3), the image the
        wavefront traces bit for bit. ``camera`` = (eye, forward, right, up, tan_half)."""
        em, ctx, g = self.emitters, self.ctx, self.ctx.geometry
        es = self.fused_scene()
        width, height = size
        n = (r1 - r0) * width
        out = np.empty((n, 3))
        counts = np.zeros((n, 2), np.int64)
        eye, forward, right, up, tan_half = camera
        with numba.parallel_chunksize(fused.DYNAMIC_CHUNKS):  # a thread that the machine's
            fused.trace_tile(                                   # load slows takes fewer
                out, counts, (np.uint64(es.intersect), np.uint64(es.occluded), np.uint64(es.scene)),
                eye, forward, right, up, float(tan_half), width, height, r0, r1, first,
                passes, int(seed) & 0xFFFFFFFF,
                (self.rho, self.kr, self.kt, self.ior, self.emission),
                (self.ks_os, self.shininess, self.p_glossy),
                (em.cdf, em.p0, em.e1, em.e2, em.normal, em.le, float(em.total_area)),
                (g.corner_normals, g.face_normals, g.object_index, ctx.object_material),
                ctx.eps, ctx.background, RR_START, MAX_BOUNCES, self.blinn)
        self.rays += int(counts[:, 0].sum())
        self._hit_rows = counts[:, 1] > 0
        return out

    def first_hits(self, n: int) -> int:
        """Of the last :meth:`radiance` batch's first ``n`` camera rays, how many hit."""
        return int(np.count_nonzero(self._hit_rows[:n]))

    def radiance(self, origins: np.ndarray, dirs: np.ndarray, rng: np.random.Generator,
                 sampler: SobolSampler | None = None) -> np.ndarray:
        """One-sample estimates of L (N, 3) along N camera rays: the vertices' uniforms
        from ``sampler`` (Sobol', ray i being the sampler's path i) or, without one, from
        ``rng`` (independent; the numpy implementation always draws from ``rng``)."""
        if self.ctx.kernels:
            return self._radiance_kernel(origins, dirs, rng, sampler)
        n = len(origins)
        out = np.zeros((n, 3))
        beta = np.ones((n, 3))
        pixel = np.arange(n)
        # pdf (solid angle) of the diffuse bounce that spawned each ray; 0 for camera rays
        # and mirror/glass bounces, whose emitters are counted in full
        bsdf_pdf = np.zeros(n)
        o, d = origins, dirs
        for bounce in range(MAX_BOUNCES):
            if len(o) == 0:
                break
            o, d, beta, pixel, bsdf_pdf, t, surf, mat, textured = self._hit_vertex(
                out, o, d, beta, pixel, bsdf_pdf, bounce)
            _add(out, pixel, beta * self._emitted(surf, d, t, mat, bsdf_pdf))
            _add(out, pixel, beta * self._delta_lights(surf, d, mat, textured))
            rho = self.rho[mat]
            if textured is not None:
                idx, od = textured
                rho[idx] = self.kd[mat[idx], None] * od
            total = rho.mean(axis=1) + self.kr[mat] + self.kt[mat] + self.p_glossy[mat]
            p_diffuse = rho.mean(axis=1) / np.maximum(total, 1e-300)
            p_glossy = self.p_glossy[mat] / np.maximum(total, 1e-300)
            _add(out, pixel, beta * self._next_event(surf, d, mat, rho, p_diffuse, p_glossy,
                                                     rng))
            # Pick a lobe and continue the path
            o, d, beta, alive, bsdf_pdf = self._scatter(surf, d, mat, rho, beta, rng)
            if bounce >= RR_START:
                q = np.minimum(beta.max(axis=1), 0.95)
                survive = rng.random(len(q)) < q
                alive &= survive
                beta = beta / np.maximum(q, 1e-12)[:, None]
            o, d, beta, pixel, bsdf_pdf = (o[alive], d[alive], beta[alive], pixel[alive],
                                           bsdf_pdf[alive])
        return out

    def _radiance_kernel(self, origins: np.ndarray, dirs: np.ndarray,
                         rng: np.random.Generator,
                         sampler: SobolSampler | None = None) -> np.ndarray:
        """:meth:`radiance` with each path vertex in one numba call (same estimator,
        :func:`shadelab.raytrace.vertex.path_vertex`)."""
        ctx, n, em = self.ctx, len(origins), self.emitters
        out = np.zeros((n, 3))
        beta = np.ones((n, 3))
        pixel = np.arange(n)
        bsdf_pdf = np.zeros(n)
        o, d = origins, dirs
        for bounce in range(MAX_BOUNCES):
            if len(o) == 0:
                break
            o, d, beta, pixel, bsdf_pdf, t, surf, mat, textured = self._hit_vertex(
                out, o, d, beta, pixel, bsdf_pdf, bounce)
            if self.delta_lights:
                ray_kernels.add_rows(out, pixel, beta * self._delta_lights(surf, d, mat, textured),
                                 np.ones(len(pixel), np.bool_))
            mat, tables, lobes = self._textured_tables(mat, textured)
            rnd = (rng.random((len(t), 7)) if sampler is None
                   else sampler.vertex(pixel, bounce, em.cdf))
            (nee_o, nee_d, nee_t, nee_ok, nee_val, o, d, beta, bsdf_pdf,
             alive) = vertex.path_vertex(
                out, pixel, beta, bsdf_pdf, surf.position, surf.normal, surf.geo_normal,
                surf.entering, np.ascontiguousarray(d), t, mat, tables, lobes,
                (em.cdf, em.p0, em.e1, em.e2, em.normal, em.le, float(em.total_area)),
                ctx.eps, rnd, bounce >= RR_START, self.blinn)
            cand = np.flatnonzero(nee_ok)
            if len(cand):
                blocked = ctx.accel.occluded(nee_o[cand], nee_d[cand], nee_t[cand],
                                             everything=True)
                self.rays += len(cand)
                ray_kernels.add_rows(out, pixel[cand], nee_val[cand], ~blocked)
            o, d, beta, pixel, bsdf_pdf = (o[alive], d[alive], beta[alive], pixel[alive],
                                           bsdf_pdf[alive])
        return out

    def _hit_vertex(self, out, o, d, beta, pixel, bsdf_pdf, bounce: int):
        """One bounce's closest hits: paths that miss add the background and end; the rest
        come back with their surface, material indices and textured hits (both estimators)."""
        ctx = self.ctx
        hits = ctx.accel.intersect(o, d)
        self.rays += len(o)
        if bounce == 0:
            self.primary_hits += int(hits.hit.sum())
            self._hit_rows = hits.hit
        if ctx.kernels:
            ray_kernels.add_rows(out, pixel, beta * ctx.background, ~hits.hit)
        else:
            miss = ~hits.hit
            _add(out, pixel[miss], beta[miss] * ctx.background)
        keep = np.flatnonzero(hits.hit)
        o, d, beta, pixel, bsdf_pdf = o[keep], d[keep], beta[keep], pixel[keep], bsdf_pdf[keep]
        t = hits.t[keep]
        surf = ctx.surface(o, d, Hits(t, hits.tri[keep], hits.u[keep], hits.v[keep]))
        mat = ctx.object_material[surf.obj]
        return o, d, beta, pixel, bsdf_pdf, t, surf, mat, self._detail(surf, mat)

    def _detail(self, surf, mat: np.ndarray):
        """Textured hits: their bumped normals written into ``surf`` and their Od(u, v) as
        (index, Od) — None when no hit is on a textured material. The same lookups as
        Whitted and the raster (:mod:`shadelab.shading.surface_detail`)."""
        detail = self.ctx.detail
        if not detail.active or surf.hits is None:
            return None
        h = surf.hits
        parts = []
        for m in detail.details:
            idx = np.flatnonzero(mat == m)
            if len(idx):
                od, n = detail.od_and_normal(m, h.tri[idx], h.u[idx], h.v[idx],
                                             surf.normal[idx])
                surf.normal[idx] = n
                parts.append((idx, od))
        if not parts:
            return None
        return (np.concatenate([i for i, _ in parts]), np.concatenate([o for _, o in parts]))

    def _textured_tables(self, mat: np.ndarray, textured):
        """Material tables (rho, kr, kt, ior, emission) and glossy-lobe tables (ks Os, n,
        weight) with one extra row per textured hit (its kd Od(u, v)), and the hits' material
        indices pointing at those rows: the kernels stay per-material."""
        tables = (self.rho, self.kr, self.kt, self.ior, self.emission)
        lobes = (self.ks_os, self.shininess, self.p_glossy)
        if textured is None:
            return mat, tables, lobes
        idx, od = textured
        base = mat[idx]
        rows = len(self.rho)
        mat = mat.copy()
        mat[idx] = rows + np.arange(len(idx))
        rho = np.concatenate([self.rho, packing.textured_reflectance(self.kd[base], od)])
        return (mat, (rho, *(np.concatenate([t, t[base]]) for t in tables[1:])),
                tuple(np.concatenate([t, t[base]]) for t in lobes))

    def _delta_lights(self, surf, d: np.ndarray, mat: np.ndarray,
                      textured=None) -> np.ndarray:
        """The lecture's direct term of every (non stand-in) light at the hits, shadow rays
        giving S_i (objects with ``cast_shadows = false`` do not block, as in Whitted)."""
        n = len(d)
        if not self.delta_lights or n == 0:
            return np.zeros((n, 3))
        ctx = self.ctx
        pos = np.ascontiguousarray(surf.position)
        ng = np.ascontiguousarray(surf.geo_normal)
        shadow = np.zeros((len(self.delta_lights), n))
        for k in range(len(self.delta_lights)):
            origin, dirs, tmax, facing = surface_rays.shadow_rays(pos, ng, self.delta_table, k,
                                                             ctx.eps, T_INF)
            idx = np.flatnonzero(facing)
            if len(idx):
                blocked = ctx.accel.occluded(origin[idx], dirs[idx], tmax[idx])
                shadow[k, idx] = np.where(blocked, 0.0, 1.0)
                self.rays += len(idx)
        out = shading_kernels.local_shade(pos, np.ascontiguousarray(surf.normal),
                                  np.ascontiguousarray(-d), mat, self.direct_materials,
                                  self.delta_table, np.zeros(3), ctx.specular == "blinn",
                                  shadow)
        if textured is not None:  # the same terms with Od(u, v) (no ambient, no emission)
            idx, od = textured
            table = self.direct_materials[mat[idx]]  # a copy (fancy index)
            table[:, packing.M_OD:packing.M_OD + 3] = od
            out[idx] = shading_kernels.local_shade(pos[idx], np.ascontiguousarray(surf.normal[idx]),
                                           np.ascontiguousarray(-d[idx]),
                                           np.arange(len(idx)), np.ascontiguousarray(table),
                                           self.delta_table, np.zeros(3),
                                           ctx.specular == "blinn",
                                           np.ascontiguousarray(shadow[:, idx]))
        return out

    def _emitted(self, surf, d: np.ndarray, t: np.ndarray, mat: np.ndarray,
                 bsdf_pdf: np.ndarray) -> np.ndarray:
        """Le at the hits, MIS-weighted (balance heuristic) after a diffuse or glossy bounce."""
        le = self.emission[mat]
        weight = np.ones(len(t))
        mis = np.flatnonzero((bsdf_pdf > 0.0) & (le.max(axis=1) > 0.0))
        if len(mis):
            cos_y = np.abs(np.einsum("ij,ij->i", surf.geo_normal[mis], d[mis]))
            light_pdf = t[mis] ** 2 / np.maximum(cos_y * self.emitters.total_area, 1e-300)
            weight[mis] = bsdf_pdf[mis] / (bsdf_pdf[mis] + light_pdf)
        return le * weight[:, None]

    def _next_event(self, surf, d: np.ndarray, mat: np.ndarray, rho: np.ndarray,
                    p_diffuse: np.ndarray, p_glossy: np.ndarray,
                    rng: np.random.Generator) -> np.ndarray:
        """Direct light from one emitter point per path vertex, MIS-weighted lobe by lobe.

        f Le cos_x / (pdf_light + pdf_bsdf) per lobe, pdf_light = d^2 / (cos_y A_total) and
        pdf_bsdf = P(diffuse lobe) cos_x / pi for f = rho / pi, P(glossy lobe) pdf_glossy for
        f_s (the balance heuristic).
        """
        m = len(rho)
        out = np.zeros((m, 3))
        em = self.emitters
        idx = np.flatnonzero((rho.max(axis=1) > 0.0) | (p_glossy > 0.0))
        if em.count == 0 or len(idx) == 0:
            return out
        points, normals, le = em.sample(rng, len(idx))
        p, n, ng = surf.position[idx], surf.normal[idx], surf.geo_normal[idx]
        delta = points - p
        dist = np.linalg.norm(delta, axis=1)
        wi = delta / np.maximum(dist, 1e-300)[:, None]
        cos_x = np.einsum("ij,ij->i", n, wi)
        cos_y = np.abs(np.einsum("ij,ij->i", normals, wi))
        ok = np.flatnonzero((cos_x > 0.0) & (np.einsum("ij,ij->i", ng, wi) > 0.0)
                            & (dist > 2.0 * self.ctx.eps))
        if len(ok) == 0:
            return out
        eps = self.ctx.eps
        start = p[ok] + eps * ng[ok]
        blocked = self.ctx.accel.occluded(start, wi[ok], dist[ok] * (1.0 - 1e-4) - 2.0 * eps,
                                          everything=True)
        self.rays += len(ok)
        vis = ok[~blocked]
        light_pdf = dist[vis] ** 2 / np.maximum(cos_y[vis] * em.total_area, 1e-300)
        bsdf_pdf = p_diffuse[idx[vis]] * cos_x[vis] / np.pi
        scale = cos_x[vis] / (light_pdf + bsdf_pdf)
        out[idx[vis]] = (rho[idx[vis]] / np.pi) * le[vis] * scale[:, None]
        g = np.flatnonzero(p_glossy[idx[vis]] > 0.0)  # f_s cos = ks Os lobe / pi
        if len(g):
            at, mg = idx[vis[g]], mat[idx[vis[g]]]
            lobe, pdf = glossy_lobe_pdf(wi[vis[g]], n[vis[g]], -d[at], self.shininess[mg],
                                        self.blinn)
            out[at] += self.ks_os[mg] * le[vis[g]] * (
                lobe / np.pi / (light_pdf[g] + p_glossy[at] * pdf))[:, None]
        return out

    def _scatter(self, surf, d: np.ndarray, mat: np.ndarray, rho: np.ndarray,
                 beta: np.ndarray, rng: np.random.Generator):
        """New origins, directions and throughputs after one lobe choice per path."""
        m = len(d)
        p_d, p_r, p_t, p_s = rho.mean(axis=1), self.kr[mat], self.kt[mat], self.p_glossy[mat]
        total = p_d + p_r + p_t + p_s
        u = rng.random(m) * total
        diffuse = u < p_d
        shiny = ~diffuse & (p_s > 0.0) & (u < p_d + p_s)
        mirror = ~diffuse & ~shiny & (u < p_d + p_s + p_r)
        glass = ~diffuse & ~shiny & ~mirror & (total > 0.0)
        alive = total > 0.0
        prob = np.where(diffuse, p_d, np.where(shiny, p_s, np.where(mirror, p_r, p_t))
                        ) / np.maximum(total, 1e-300)
        new_d = np.empty_like(d)
        weight = np.zeros((m, 3))
        # Diffuse: cosine-weighted, f cos / pdf = rho
        i = np.flatnonzero(diffuse)
        new_d[i] = cosine_directions(surf.normal[i], rng)
        weight[i] = rho[i]
        alive[i] &= np.einsum("ij,ij->i", new_d[i], surf.geo_normal[i]) > 0.0
        # Mirror: kr
        refl, refr, tir, f = reflect_refract(d, surf.normal, surf.entering, self.ior[mat])
        i = np.flatnonzero(mirror)
        new_d[i] = refl[i]
        weight[i] = self.kr[mat[i]][:, None]
        # Glass: Fresnel picks reflection (F) or refraction (1 - F); weight kt
        i = np.flatnonzero(glass)
        reflect = rng.random(len(i)) < f[i]
        new_d[i] = np.where(reflect[:, None], refl[i], refr[i])
        weight[i] = self.kt[mat[i]][:, None]
        through = np.zeros(m, bool)
        through[i] = ~reflect
        # Glossy: the lobe about R (or H about N), f_s cos / pdf = ks Os weight
        g = np.flatnonzero(shiny)
        u1, u2 = rng.random(len(g)), rng.random(len(g))
        v, n, ng = -d[g], surf.normal[g], surf.geo_normal[g]
        new_d[g], w = glossy_directions(n, v, self.shininess[mat[g]], self.blinn, u1, u2)
        weight[g] = self.ks_os[mat[g]] * np.broadcast_to(w, len(g))[:, None]
        alive[g] &= (np.broadcast_to(w, len(g)) > 0.0) & (_dot(new_d[g], ng) > 0.0) \
            & (_dot(new_d[g], n) > 0.0)
        side = np.where(through, -1.0, 1.0) * self.ctx.eps
        origins = surf.position + side[:, None] * surf.geo_normal
        beta = beta * weight / np.maximum(prob, 1e-300)[:, None]
        bsdf_pdf = np.zeros(m)
        i = np.flatnonzero(diffuse)
        bsdf_pdf[i] = prob[i] * np.einsum("ij,ij->i", new_d[i], surf.normal[i]) / np.pi
        bsdf_pdf[g] = prob[g] * glossy_lobe_pdf(new_d[g], n, v, self.shininess[mat[g]],
                                                self.blinn)[1]
        return origins, new_d, beta, alive, bsdf_pdf


def _add(out: np.ndarray, pixel: np.ndarray, value: np.ndarray) -> None:
    if len(pixel):
        for c in range(3):
            out[:, c] += np.bincount(pixel, weights=value[:, c], minlength=len(out))


def passes_per_job(size: tuple[int, int], spp: int, fused: bool = False) -> int:
    """Sample passes per job: an image smaller than a tile traces several in one wavefront
    of up to WAVEFRONT_PATHS paths (the per-bounce overheads shared), in at least
    min(spp, 4) jobs (progress to show, a cancel to honour). ``fused`` (whole paths in one
    call): tiles and calls of up to FUSED_TILE_PATHS paths, a pixel's passes in a row (at
    128 x 128 x 64 on cornell: 1.85 us of CPU a sample against 1.9 to 2.4 one pass a call)."""
    pixels = size[0] * size[1]
    tile, paths = (FUSED_TILE_PATHS, FUSED_TILE_PATHS) if fused else (TILE_PATHS,
                                                                     WAVEFRONT_PATHS)
    if pixels >= tile:
        return 1
    return max(1, min(-(-spp // 4), paths // pixels))


def iter_pathtrace(scene: Scene, size: tuple[int, int], spp: int, seed: int = 0,
                   backend: str = "auto", local: str = "numba",
                   workers: int = 1, sampler: str | None = None) -> Iterator[Progress]:
    """Path-trace progressively: one :class:`Progress` per tile of rows per sample pass.

    The image in each Progress is the mean over the samples each pixel has so far
    (radiance, float32, row 0 at the top); stats hold samples/s and rays/s. Each tile of
    each pass draws from its own random stream (``seed``, pass, first row), so the image
    is the same for any number of ``workers`` (processes; 1 traces here).

    ``sampler`` (default: the scene's ``raytrace.sampler``) is ``"sobol"``, Owen-scrambled
    Sobol' per pixel (:mod:`shadelab.raytrace.sampler`; sample pass s is each pixel's
    Sobol' index s, so power-of-two sample counts stratify best), or ``"independent"``
    uniforms from each tile's stream.
    """
    sampler = scene.raytrace.sampler if sampler is None else sampler
    if sampler not in SAMPLERS:
        raise ShadeLabError(f"sampler {sampler!r}: expected one of {', '.join(SAMPLERS)}")
    width, height = size
    if width < 1 or height < 1:
        raise ShadeLabError(f"--size {width}x{height}: expected each side >= 1")
    if spp < 1:
        raise ShadeLabError(f"--spp {spp}: expected an integer >= 1")
    setup = (scene, size, spp, seed, backend, local, sampler)
    job_fn = TileJob(*setup) if workers <= 1 else None
    # whole paths in one call: larger tiles (fewer Progress images to copy and send)
    tile_paths = FUSED_TILE_PATHS if job_fn is not None and job_fn.fused else TILE_PATHS
    rows = max(1, tile_paths // width)
    tiles = [(r, min(r + rows, height)) for r in range(0, height, rows)]
    batch = passes_per_job(size, spp, tile_paths == FUSED_TILE_PATHS)
    jobs = [(sample, r0, r1, min(batch, spp - sample)) for sample in range(0, spp, batch)
            for r0, r1 in tiles]
    if workers > 1 and len(jobs) > 1:
        from shadelab.raytrace.pool import traced_in_pool

        results = traced_in_pool(_init_worker, setup, _trace_tile, jobs, lambda job: job,
                                 workers)
        name = "embree" if backend == "embree" or (backend == "auto" and embree_available()) \
            else "bvh"
    else:
        job_fn = TileJob(*setup) if job_fn is None else job_fn
        results = ((job, job_fn(*job)) for job in jobs)
        name = job_fn.tracer.ctx.accel.name
    total = np.zeros((height * width, 3))
    count = np.zeros(height * width)
    image = np.zeros((height, width, 3), np.float32)
    rays = hits = 0
    start = time.perf_counter()
    for done, ((sample, r0, r1, passes), (radiance, tile_rays, tile_hits)) in enumerate(
            results, 1):
        rays += tile_rays
        hits += tile_hits if sample == 0 else 0
        part = slice(r0 * width, r1 * width)
        total[part] += radiance
        count[part] += passes
        image[r0:r1] = (total[part] / count[part, None]).reshape(r1 - r0, width, 3)
        elapsed = time.perf_counter() - start
        samples = int(count.sum())
        stats = {"samples": samples, "seconds": elapsed, "rays": rays,
                 "samples_per_s": samples / elapsed if elapsed > 0 else 0.0,
                 "rays_per_s": rays / elapsed if elapsed > 0 else 0.0,
                 "primary_hits": hits if done >= len(tiles) else 1,
                 "backend": name, "spp": spp, "workers": workers}
        yield Progress(image.copy(), done / len(jobs),
                       f"sample {sample + passes}/{spp}, rows {r1}/{height}", stats)


class TileJob:
    """Traces tile (pass, r0, r1, passes): its jittered camera rays and one path per pixel
    for each of the passes pass .. pass + passes - 1, all in one wavefront."""

    def __init__(self, scene: Scene, size: tuple[int, int], spp: int, seed: int,
                 backend: str, local: str, sampler: str = "sobol"):
        from shadelab.scene.camera import (  # the camera's own frame, so the images align
            camera_basis,
            tan_half_fov_y,
        )

        self.tracer = PathTracer(scene, backend, local=local)
        self.size, self.spp, self.seed, self.sampler = size, spp, seed, sampler
        cam = scene.camera
        self.frame = camera_basis(cam)
        self.eye = np.asarray(cam.eye, dtype=np.float64)
        self.tan_half = tan_half_fov_y(cam, size[0] / size[1])

    @property
    def fused(self) -> bool:
        """Whole paths in one numba call (:meth:`PathTracer.trace_tile`) for this job."""
        return self.sampler == "sobol" and self.tracer.fused_scene() is not None

    def __call__(self, sample: int, r0: int, r1: int, passes: int = 1):
        """(radiance summed over the passes (n, 3), rays cast, primary hits of the first
        pass) of one tile."""
        width, height = self.size
        n = (r1 - r0) * width
        if self.fused:
            before_rays = self.tracer.rays
            radiance = self.tracer.trace_tile(
                (self.eye, *self.frame, self.tan_half), self.size, r0, r1, sample, passes,
                self.seed)
            return radiance, self.tracer.rays - before_rays, self.tracer.first_hits(n)
        rng = np.random.default_rng([self.seed, sample, r0] if passes == 1
                                    else [self.seed, sample, r0, passes])
        sobol = None
        if self.sampler == "sobol":  # pixel positions: each pixel's Sobol' pair 0
            sobol = SobolSampler(self.seed, np.tile(r0 * width + np.arange(n), passes),
                                 np.repeat(sample + np.arange(passes), n))
            jitters = sobol.jitter().reshape(passes, r1 - r0, width, 2)
        else:  # stratified pixel positions: sample s jitters inside stratum s
            jitters = [rng.random((r1 - r0, width, 2)) if self.spp == 1
                       else stratified_jitter(self.spp, s, (r1 - r0, width), rng)
                       for s in range(sample, sample + passes)]
        forward, right, up = self.frame
        rays = [ray_kernels.camera_rays(self.eye, forward, right, up, self.tan_half, width,
                                        height, r0, r1, jitter) for jitter in jitters]
        o = rays[0][0] if passes == 1 else np.concatenate([r[0] for r in rays])
        d = rays[0][1] if passes == 1 else np.concatenate([r[1] for r in rays])
        before_rays = self.tracer.rays
        radiance = self.tracer.radiance(o, d, rng, sobol)
        if passes > 1:
            radiance = radiance.reshape(passes, n, 3).sum(axis=0)
        return radiance, self.tracer.rays - before_rays, self.tracer.first_hits(n)


_WORKER_JOB: TileJob | None = None


def _init_worker(*setup) -> None:
    global _WORKER_JOB
    _WORKER_JOB = TileJob(*setup)


def _trace_tile(sample: int, r0: int, r1: int, passes: int = 1):
    return _WORKER_JOB(sample, r0, r1, passes)


def render_pathtraced(scene: Scene, size: tuple[int, int], spp: int, seed: int = 0,
                      workers: int = 1, sampler: str | None = None) -> np.ndarray:
    """Path-traced radiance (H, W, 3) float32, row 0 at the top (Embree where available).

    ``workers`` > 1 traces tiles in that many processes (same image; worth it from about
    a million samples, each worker takes a second or two to start); ``sampler`` as in
    :func:`iter_pathtrace`.
    """
    last = None
    for step in iter_pathtrace(scene, size, spp, seed, workers=workers, sampler=sampler):
        last = step
    return last.image
