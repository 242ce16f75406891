"""The pixel probe: which surface point a viewport pixel shows, and the lecture's terms there.

Pure numpy (no GL): a ray through the pixel centre (``primary_rays``, aligned with the raster
image) is cast against the scene's MeshData triangles with the ray tracer's acceleration
structure (Embree, or the numba BVH without it: :mod:`shadelab.raytrace.accel`); the reference
equation
(:func:`shadelab.shading.reference.shade_terms`) is evaluated the way the chosen shading mode does:

- flat: once per triangle at its centroid, with the face normal;
- Gouraud: at the three corners with their vertex normals, blended by the barycentrics;
- Phong: at the point itself, with the barycentric blend of the corner normals, renormalized.

In every mode the normal is flipped when the face is seen from behind, as the shaders do.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from shadelab.geometry.mesh import MeshData, scene_meshes
from shadelab.geometry.normals import threshold_at
from shadelab.raytrace.accel import build_accel, scene_geometry
from shadelab.scene.camera import primary_rays
from shadelab.scene.model import Scene
from shadelab.shading.lights import light_kind
from shadelab.shading.reference import ShadeTerms, halfway, normalize, reflect_light, shade_terms


@dataclass
class Hit:
    """The nearest surface point along a ray."""

    mesh: MeshData
    face: int                 # triangle index in ``mesh.faces``
    t: float                  # ray parameter, world units
    point: np.ndarray         # (3,) world space
    bary: np.ndarray          # (3,) barycentric weights of the triangle's corners


@dataclass
class ProbeResult:
    """What the probe panel shows for one pixel."""

    pixel: tuple[int, int]    # (x, y), row 0 at the top
    hit: Hit
    shading: str
    specular: str
    normal: np.ndarray        # (3,) unit, facing the viewer (the N used at ``point``)
    to_eye: np.ndarray        # (3,) unit V
    terms: ShadeTerms         # the terms at ``point`` (Phong-style, for the arrows and table)
    reference: np.ndarray     # (3,) what the chosen shading mode computes at this pixel
    gpu: np.ndarray | None = None  # (3,) what the GPU drew, filled in by the viewer

    @property
    def point(self) -> np.ndarray:
        return self.hit.point

    def reflected(self, i: int) -> np.ndarray:
        """R_i (Phong) or H_i (Blinn-Phong) for light i."""
        to_light = self.terms.lights[i].to_light
        if self.specular == "blinn":
            return halfway(to_light, self.to_eye)
        return reflect_light(self.normal, to_light)


class Picker:
    """The scene's triangles in the ray tracer's accelerator, answering in MeshData terms."""

    def __init__(self, scene: Scene, meshes: list[MeshData]):
        self.meshes = meshes
        self.accel = build_accel(scene_geometry(scene, meshes))
        self.starts = np.cumsum([0] + [len(m.faces) for m in meshes])  # first triangle of each

    def hits(self, origins: np.ndarray, directions: np.ndarray):
        """Nearest hits of (R, 3) rays: mesh index (-1 = miss), face, t, barycentrics (R, 3)."""
        hits = self.accel.intersect(origins, directions)
        hit = hits.tri >= 0
        mesh_id = np.where(hit, np.searchsorted(self.starts, hits.tri, side="right") - 1, -1)
        face = np.where(hit, hits.tri - self.starts[np.maximum(mesh_id, 0)], 0)
        bary = np.stack([1.0 - hits.u - hits.v, hits.u, hits.v], axis=1)
        return mesh_id, face, hits.t, np.where(hit[:, None], bary, 0.0)


def intersect_many(scene: Scene, meshes: list[MeshData], origins: np.ndarray,
                   directions: np.ndarray):
    """Nearest hits of (R, 3) rays (see :meth:`Picker.hits`)."""
    return Picker(scene, meshes).hits(origins, directions)


def intersect(scene: Scene, meshes: list[MeshData], origin: np.ndarray,
              direction: np.ndarray) -> Hit | None:
    """Nearest hit of one ray against every triangle of ``meshes``."""
    mesh_id, face, t, bary = intersect_many(scene, meshes, origin[None], direction[None])
    if mesh_id[0] < 0:
        return None
    return Hit(meshes[mesh_id[0]], int(face[0]), float(t[0]), origin + t[0] * direction, bary[0])


def cast_pixel(scene: Scene, size: tuple[int, int], pixel: tuple[int, int],
               meshes: list[MeshData] | None = None) -> Hit | None:
    """The surface point seen through pixel (x, y) of a (width, height) image."""
    width, height = size
    x, y = pixel
    origins, directions = primary_rays(scene.camera, width, height)
    meshes = scene_meshes(scene) if meshes is None else meshes
    return intersect(scene, meshes, origins[y, x], directions[y, x])


def probe_shadows(scene: Scene, point: np.ndarray, geometric_normal: np.ndarray,
                  lights) -> list[np.ndarray]:
    """(3,) S_i per light at ``point`` as the raster's shadow volumes give it: one shadow ray
    of the ray tracer towards the light, 1 if it gets there, 0 behind an opaque caster, the
    product of kt Ot over the transparent casters it crosses (kt-filtered shadows)."""
    from shadelab.constants import T_INF
    from shadelab.raytrace.surface import TraceContext

    ctx = TraceContext(scene)
    origin = np.asarray(point, dtype=np.float64) + ctx.eps * geometric_normal
    out = []
    for light in lights:
        if light_kind(light).at_infinity:
            d, tmax = normalize(-np.asarray(light.direction, dtype=np.float64)), T_INF
        else:
            delta = np.asarray(light.position, dtype=np.float64) - origin
            distance = float(np.linalg.norm(delta))
            d, tmax = delta / max(distance, 1e-300), max(distance - ctx.eps, 0.0)
        out.append(ctx.shadow_transmittance(origin[None], d[None], np.array([tmax]))[0])
    return out


def _facing(n: np.ndarray, face_normal: np.ndarray, to_eye: np.ndarray) -> np.ndarray:
    """Flip ``n`` where the face is seen from behind (the shaders' back-face rule)."""
    sign = np.where(np.sum(face_normal * to_eye, axis=-1) < 0.0, -1.0, 1.0)
    return n * sign[..., None]


def probe(scene: Scene, size: tuple[int, int], pixel: tuple[int, int], shading: str | None = None,
          specular: str | None = None, meshes: list[MeshData] | None = None,
          off=()) -> ProbeResult | None:
    """Every term of the lecture's equation at the surface point under ``pixel``; None on a miss.
    ``off``: the terms switched off (:func:`shadelab.shading.reference.shade_terms`), as the
    viewport draws them."""
    shading = shading or scene.render.shading
    specular = specular or scene.render.specular
    hit = cast_pixel(scene, size, pixel, meshes)
    if hit is None:
        return None
    mesh, face = hit.mesh, hit.face
    material = scene.materials[mesh.material]
    lights = scene.active_lights()
    eye = np.asarray(scene.camera.eye, dtype=np.float64)
    fn = mesh.face_normals[face]
    corners = mesh.triangles[face]
    to_eye = normalize(eye - hit.point)
    if shading == "flat":
        normal = _facing(fn, fn, to_eye)
    else:
        normal = _facing(normalize(hit.bary @ mesh.corner_normals[face]), fn, to_eye)
    shadow, fade = None, 0.0
    if scene.render.shadows == "volumes" and material.kt <= 0.0 and lights \
            and "shadow" not in off:
        # the stencil's S_i at this pixel; transparent surfaces are drawn unshadowed
        shadow = probe_shadows(scene, hit.point, _facing(fn, fn, to_eye), lights)
        if shading != "flat":  # the point's own threshold (geometry/normals.threshold_at)
            fade = threshold_at(mesh.corner_terminators[face], mesh.corner_normals[face],
                                np.asarray(hit.bary, dtype=np.float64))
    terms = shade_terms(hit.point, normal, eye, material, lights, scene.Ia, specular, shadow,
                        terminator=fade, off=off)
    if shading == "flat":
        centroid = corners.mean(axis=0)
        n_c = _facing(fn, fn, normalize(eye - centroid))
        reference = shade_terms(centroid, n_c, eye, material, lights, scene.Ia, specular,
                                shadow, off=off).total
    elif shading == "gouraud":
        n_v = _facing(mesh.corner_normals[face], np.broadcast_to(fn, (3, 3)), eye - corners)
        at_corners = None if shadow is None else [np.broadcast_to(s, (3, 3)) for s in shadow]
        at_t = 0.0 if shadow is None else mesh.corner_terminators[face]  # the corners' t_v
        colors = shade_terms(corners, n_v, eye, material, lights, scene.Ia, specular,
                             at_corners, terminator=at_t, off=off).total
        reference = hit.bary @ colors
    else:
        reference = terms.total
    return ProbeResult(pixel, hit, shading, specular, normal, to_eye, terms,
                       np.asarray(reference, dtype=np.float64))

