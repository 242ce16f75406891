"""The pixel probe: which surface point a viewport pixel shows, and the lecture's terms there.

Pure numpy (no GL): a ray through the pixel centre (``primary_rays``, aligned with the raster
image) is cast against the scene's MeshData triangles; the reference equation
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
from shadelab.scene.camera import primary_rays
from shadelab.scene.model import Scene
from shadelab.shading.reference import ShadeTerms, halfway, normalize, reflect_light, shade_terms

_EPS = 1e-12


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


def intersect(meshes: list[MeshData], origin: np.ndarray, direction: np.ndarray) -> Hit | None:
    """Nearest hit of one ray against every triangle (Moller-Trumbore, vectorized)."""
    best: Hit | None = None
    for mesh in meshes:
        tri = mesh.triangles
        e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
        p = np.cross(direction, e2)
        det = np.einsum("ij,ij->i", e1, p)
        ok = np.abs(det) > _EPS
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        s = origin - tri[:, 0]
        u = np.einsum("ij,ij->i", s, p) * inv
        q = np.cross(s, e1)
        v = (q @ direction) * inv
        t = np.einsum("ij,ij->i", e2, q) * inv
        valid = ok & (u >= -1e-9) & (v >= -1e-9) & (u + v <= 1 + 1e-9) & (t > 1e-9)
        if not valid.any():
            continue
        face = int(np.flatnonzero(valid)[np.argmin(t[valid])])
        if best is None or t[face] < best.t:
            bary = np.array([1.0 - u[face] - v[face], u[face], v[face]])
            best = Hit(mesh, face, float(t[face]), origin + t[face] * direction, bary)
    return best


def cast_pixel(scene: Scene, size: tuple[int, int], pixel: tuple[int, int],
               meshes: list[MeshData] | None = None) -> Hit | None:
    """The surface point seen through pixel (x, y) of a (width, height) image."""
    width, height = size
    x, y = pixel
    origins, directions = primary_rays(scene.camera, width, height)
    meshes = scene_meshes(scene) if meshes is None else meshes
    return intersect(meshes, origins[y, x], directions[y, x])


def _facing(n: np.ndarray, face_normal: np.ndarray, to_eye: np.ndarray) -> np.ndarray:
    """Flip ``n`` where the face is seen from behind (the shaders' back-face rule)."""
    sign = np.where(np.sum(face_normal * to_eye, axis=-1) < 0.0, -1.0, 1.0)
    return n * sign[..., None]


def probe(scene: Scene, size: tuple[int, int], pixel: tuple[int, int], shading: str | None = None,
          specular: str | None = None, meshes: list[MeshData] | None = None) -> ProbeResult | None:
    """Every term of the lecture's equation at the surface point under ``pixel``; None on a miss."""
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
    terms = shade_terms(hit.point, normal, eye, material, lights, scene.Ia, specular)
    if shading == "flat":
        centroid = corners.mean(axis=0)
        n_c = _facing(fn, fn, normalize(eye - centroid))
        reference = shade_terms(centroid, n_c, eye, material, lights, scene.Ia, specular).total
    elif shading == "gouraud":
        n_v = _facing(mesh.corner_normals[face], np.broadcast_to(fn, (3, 3)), eye - corners)
        colors = shade_terms(corners, n_v, eye, material, lights, scene.Ia, specular).total
        reference = hit.bary @ colors
    else:
        reference = terms.total
    return ProbeResult(pixel, hit, shading, specular, normal, to_eye, terms,
                       np.asarray(reference, dtype=np.float64))


def intersect_many(meshes: list[MeshData], origins: np.ndarray, directions: np.ndarray,
                   budget: int = 2_000_000):
    """Nearest hits of (R, 3) rays: mesh index (-1 = miss), face, t, barycentrics (R, 3)."""
    count = len(origins)
    best_t = np.full(count, np.inf)
    mesh_id = np.full(count, -1)
    face_id = np.zeros(count, np.int64)
    bary = np.zeros((count, 3))
    for m, mesh in enumerate(meshes):
        tri = mesh.triangles
        e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
        step = max(1, budget // max(len(tri), 1))
        for r0 in range(0, count, step):
            o, d = origins[r0:r0 + step, None, :], directions[r0:r0 + step, None, :]
            p = np.cross(d, e2[None])
            det = np.sum(e1[None] * p, axis=-1)
            ok = np.abs(det) > _EPS
            inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
            s = o - tri[None, :, 0]
            u = np.sum(s * p, axis=-1) * inv
            q = np.cross(s, e1[None])
            v = np.sum(q * d, axis=-1) * inv
            t = np.sum(e2[None] * q, axis=-1) * inv
            valid = ok & (u >= -1e-9) & (v >= -1e-9) & (u + v <= 1 + 1e-9) & (t > 1e-9)
            t = np.where(valid, t, np.inf)
            f = np.argmin(t, axis=1)
            rows = np.arange(len(f))
            tf = t[rows, f]
            closer = tf < best_t[r0:r0 + step]
            idx = np.flatnonzero(closer) + r0
            best_t[idx] = tf[closer]
            mesh_id[idx] = m
            face_id[idx] = f[closer]
            uf, vf = u[rows, f][closer], v[rows, f][closer]
            bary[idx] = np.stack([1.0 - uf - vf, uf, vf], axis=1)
    return mesh_id, face_id, best_t, bary
