"""Scene objects to world-space triangle meshes (trimesh primitives or mesh files).

Every renderer reads the same :class:`MeshData`, so raster, ray-traced and radiosity images
show the same triangles.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property, lru_cache
from pathlib import Path

import numpy as np
from pyrr import matrix33

from shadelab import limits
from shadelab.errors import ShadeLabError
from shadelab.geometry import cache
from shadelab.geometry.normals import corner_normals, face_areas, face_normals, terminator_threshold
from shadelab.paths import file_problem
from shadelab.progress import busy, steps
from shadelab.scene.model import LENGTH_MAX, Object, Scene

MESH_SUFFIXES = (".obj", ".ply", ".stl", ".gltf", ".glb", ".off")


@dataclass
class MeshData:
    """One object's triangles in world space.

    Attributes
    ----------
    vertices : (V, 3) float64, world space
    faces : (F, 3) int64, counter-clockwise seen from the front
    uvs : (V, 2) float64 texture coordinates
    face_normals : (F, 3) float64, unit
    corner_normals : (F, 3, 3) float64, unit, by the object's normals mode
    """

    index: int
    material: str
    vertices: np.ndarray
    faces: np.ndarray
    uvs: np.ndarray
    face_normals: np.ndarray
    corner_normals: np.ndarray

    @property
    def triangles(self) -> np.ndarray:
        """(F, 3, 3) corner positions."""
        return self.vertices[self.faces]

    @property
    def areas(self) -> np.ndarray:
        return face_areas(self.vertices, self.faces)

    @cached_property
    def terminator(self) -> float:
        """sin of the widest face-to-corner normal angle (see :func:`terminator_threshold`)."""
        return terminator_threshold(self.face_normals, self.corner_normals)


def geometry_key(obj: Object, base_dir: str) -> tuple:
    """Everything that changes an object's triangles (not its material)."""
    return (obj.shape, obj.path, base_dir, obj.radius, obj.minor_radius, obj.height,
            tuple(obj.extents), obj.size, tuple(map(tuple, obj.vertices)), obj.subdivisions,
            obj.sections, obj.segments, tuple(obj.translate), tuple(obj.rotate),
            tuple(obj.scale), obj.normals, obj.crease_angle)


def object_mesh(obj: Object, index: int = 0, base_dir: str = ".") -> MeshData:
    """Build an object's world-space mesh and normals (cached on its geometry key)."""
    vertices, faces, uvs, fn, cn = _cached_mesh(geometry_key(obj, base_dir), obj.shape, index)
    return MeshData(index, obj.material, vertices, faces, uvs, fn, cn)


def scene_meshes(scene: Scene) -> list[MeshData]:
    """Every object's mesh; the scene's triangles stay within limits.MAX_TRIANGLES (one file
    over it is refused by load_mesh_file before its normals are built)."""
    meshes = []
    total = 0
    for i, obj in steps(enumerate(scene.objects), len(scene.objects), "meshes and normals"):
        meshes.append(object_mesh(obj, i, scene.base_dir))
        total += len(meshes[-1].faces)
        limits.check(f"objects: the scene's first {i + 1} meshes", total, limits.MAX_TRIANGLES,
                     "triangles")
    return meshes


def scene_bounds(meshes: list[MeshData]) -> np.ndarray:
    """(2, 3) min and max corner over all meshes; a unit box when the scene is empty."""
    if not meshes:
        return np.array([[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]])
    points = np.concatenate([m.vertices for m in meshes])
    return np.stack([points.min(axis=0), points.max(axis=0)])


@lru_cache(maxsize=256)
def _cached_mesh(key: tuple, shape: str, index: int):
    obj = _object_from_key(key)
    vertices, faces, uvs = _local_mesh(obj, key[2], index)
    matrix = world_from_object(obj)
    vertices = vertices @ matrix[:3, :3].T + matrix[:3, 3]
    if np.linalg.det(matrix[:3, :3]) < 0.0:  # a mirroring scale flips the winding back
        faces = faces[:, ::-1].copy()
    fn = face_normals(vertices, faces)
    name = cache.key("normals", vertices, faces, obj.normals, obj.crease_angle)
    hit = cache.load(name)
    if hit is not None and hit.get("corner_normals", np.empty(0)).shape == (len(faces), 3, 3):
        cn = hit["corner_normals"]
    else:
        with busy(f"objects.{index}: {len(faces)} triangles' normals"):
            cn = corner_normals(vertices, faces, obj.normals, obj.crease_angle)
        cache.store(name, {"corner_normals": cn})
    for array in (vertices, faces, uvs, fn, cn):
        array.setflags(write=False)
    return vertices, faces, uvs, fn, cn


def _object_from_key(key: tuple) -> Object:
    (shape, path, _base, radius, minor, height, extents, size, vertices, subdivisions, sections,
     segments, translate, rotate, scale, normals, crease) = key
    return Object(shape=shape, path=path, radius=radius, minor_radius=minor, height=height,
                  extents=extents, size=size, vertices=[list(v) for v in vertices],
                  subdivisions=subdivisions, sections=sections, segments=segments,
                  translate=translate, rotate=rotate, scale=scale, normals=normals,
                  crease_angle=crease)


def world_from_object(obj: Object) -> np.ndarray:
    """4x4 (column-vector) transform: scale, then rotate X, Y, Z (degrees), then translate."""
    rx, ry, rz = (math.radians(a) for a in obj.rotate)
    rotation = (matrix33.create_from_z_rotation(rz) @ matrix33.create_from_y_rotation(ry)
                @ matrix33.create_from_x_rotation(rx))   # static x, then y, then z
    matrix = np.eye(4)
    matrix[:3, :3] = rotation @ np.diag(obj.scale)
    matrix[:3, 3] = obj.translate
    return matrix


def grid(corners: np.ndarray, segments: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A bilinear patch over 4 corners (counter-clockwise), ``segments`` cells per edge."""
    t = np.linspace(0.0, 1.0, segments + 1)
    u, v = np.meshgrid(t, t, indexing="xy")
    u, v = u.reshape(-1), v.reshape(-1)
    p0, p1, p2, p3 = corners
    points = ((1 - u) * (1 - v))[:, None] * p0 + (u * (1 - v))[:, None] * p1 \
        + (u * v)[:, None] * p2 + ((1 - u) * v)[:, None] * p3
    idx = np.arange((segments + 1) ** 2).reshape(segments + 1, segments + 1)
    a, b = idx[:-1, :-1].reshape(-1), idx[:-1, 1:].reshape(-1)
    c, d = idx[1:, 1:].reshape(-1), idx[1:, :-1].reshape(-1)
    faces = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    return points, faces, np.stack([u, v], axis=1)


def _local_mesh(obj: Object, base_dir: str, index: int):
    shape = obj.shape
    if shape == "quad":
        return grid(np.asarray(obj.vertices, dtype=np.float64), obj.segments)
    if shape == "plane":
        h = obj.size / 2.0
        corners = np.array([[-h, 0, h], [h, 0, h], [h, 0, -h], [-h, 0, -h]])
        return grid(corners, obj.segments)
    if shape == "mesh":
        mesh = load_mesh_file(obj.path, base_dir, f"objects.{index}.path")
        vertices = np.asarray(mesh.vertices, dtype=np.float64)
        faces = np.asarray(mesh.faces, dtype=np.int64)
        return vertices, faces, _projected_uvs(vertices, shape)
    name = cache.key("primitive", shape, obj.radius, obj.minor_radius, obj.height,
                     tuple(obj.extents), obj.subdivisions, obj.sections)
    hit = cache.load(name)
    if _sound(hit):
        vertices, faces = hit["vertices"], hit["faces"]
    else:
        vertices, faces = _primitive(obj, index)
        cache.store(name, {"vertices": vertices, "faces": faces})
    return vertices, faces, _projected_uvs(vertices, shape)


def _sound(hit: dict | None) -> bool:
    """A cached primitive that is what it says: (V, 3) float64, (F, 3) int64 in range."""
    if hit is None or not {"vertices", "faces"} <= hit.keys():
        return False
    v, f = hit["vertices"], hit["faces"]
    return (v.dtype == np.float64 and v.ndim == 2 and v.shape[1] == 3 and f.dtype == np.int64
            and f.ndim == 2 and f.shape[1] == 3 and len(f) > 0
            and 0 <= int(f.min()) and int(f.max()) < len(v) and bool(np.isfinite(v).all()))


def _primitive(obj: Object, index: int) -> tuple[np.ndarray, np.ndarray]:
    """A trimesh primitive's vertices (V, 3) float64 and faces (F, 3) int64."""
    import trimesh

    shape = obj.shape
    if shape == "sphere":
        mesh = trimesh.creation.icosphere(subdivisions=obj.subdivisions, radius=obj.radius)
    elif shape == "box":
        mesh = trimesh.creation.box(extents=obj.extents)
    elif shape == "cylinder":
        mesh = trimesh.creation.cylinder(radius=obj.radius, height=obj.height,
                                         sections=obj.sections)
    elif shape == "cone":
        mesh = trimesh.creation.cone(radius=obj.radius, height=obj.height, sections=obj.sections)
    elif shape == "capsule":
        mesh = trimesh.creation.capsule(height=obj.height, radius=obj.radius,
                                        count=[obj.sections, obj.sections])
    elif shape == "torus":
        mesh = trimesh.creation.torus(major_radius=obj.radius, minor_radius=obj.minor_radius,
                                      major_sections=obj.sections,
                                      minor_sections=max(obj.sections // 2, 3))
    else:
        raise ShadeLabError(f"objects.{index}.shape: unknown shape {shape!r}")
    return (np.asarray(mesh.vertices, dtype=np.float64),
            np.asarray(mesh.faces, dtype=np.int64))


def _projected_uvs(vertices: np.ndarray, shape: str) -> np.ndarray:
    """Spherical uvs for round shapes, a planar xz projection otherwise."""
    if shape in ("sphere", "torus", "capsule"):
        d = vertices / np.maximum(np.linalg.norm(vertices, axis=1, keepdims=True), 1e-12)
        u = 0.5 + np.arctan2(d[:, 2], d[:, 0]) / (2 * np.pi)
        v = 0.5 + np.arcsin(np.clip(d[:, 1], -1, 1)) / np.pi
        return np.stack([u, v], axis=1)
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    span = np.maximum(hi - lo, 1e-12)
    return np.stack([(vertices[:, 0] - lo[0]) / span[0], (vertices[:, 2] - lo[2]) / span[2]], 1)


def check_vertices(vertices: np.ndarray, where: str) -> None:
    """Refuse NaN, infinite or out-of-range coordinates, naming the first bad vertex.

    The limit is the field table's LENGTH_MAX: a mesh file may hold no coordinate a preset
    could not (squared distances then stay finite in float32 shaders and in Embree).
    """
    with np.errstate(invalid="ignore"):
        bad = ~np.isfinite(vertices).all(axis=1) | (np.abs(vertices) > LENGTH_MAX).any(axis=1)
    if bad.any():
        first = int(np.flatnonzero(bad)[0])
        x, y, z = (float(c) for c in vertices[first])
        what = "non-finite" if not np.isfinite(vertices[first]).all() else "out-of-range"
        raise ShadeLabError(f"{where} has {int(bad.sum())} vertices with {what} coordinates, "
                            f"first vertex {first} = ({x:g}, {y:g}, {z:g}); expected finite "
                            f"numbers within +-{LENGTH_MAX:g}")


def load_mesh_file(path: str, base_dir: str, key: str):
    """Load a mesh file, refusing what no renderer can use, with a one-line reason."""
    full = Path(path) if Path(path).is_absolute() else Path(base_dir) / path
    problem = file_problem(full)
    if problem:
        raise ShadeLabError(f"{key}: mesh file '{full}' {problem}")
    if full.suffix.lower() not in MESH_SUFFIXES:
        raise ShadeLabError(f"{key}: '{full.name}' is not a mesh file "
                            f"(expected one of {', '.join(MESH_SUFFIXES)})")
    size = full.stat().st_size
    limits.check(f"{key}: '{full.name}'", size, limits.MAX_MESH_FILE_BYTES, "bytes",
                 memory_bytes=8.0 * size)  # trimesh's arrays and its text parse
    import trimesh

    try:
        with busy(f"{key}: reading '{full.name}'"):
            mesh = trimesh.load(str(full), force="mesh", process=False)
    except Exception as exc:  # trimesh raises many types for corrupt files
        raise ShadeLabError(f"{key}: '{full.name}' could not be read as a mesh ({exc})") from None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise ShadeLabError(f"{key}: '{full.name}' holds no triangles (empty mesh)")
    check_vertices(np.asarray(mesh.vertices, dtype=np.float64), f"{key}: '{full.name}'")
    limits.check(f"{key}: '{full.name}'", len(mesh.faces), limits.MAX_TRIANGLES, "triangles",
                 memory_bytes=400.0 * len(mesh.faces))  # normals, BVH, GL buffers
    areas = face_areas(np.asarray(mesh.vertices, float), np.asarray(mesh.faces))
    degenerate = np.flatnonzero(areas <= 1e-12 * max(float(areas.max()), 1e-300))
    if len(degenerate):
        raise ShadeLabError(f"{key}: '{full.name}' has {len(degenerate)} degenerate (zero-area) "
                            f"triangles, first at face {degenerate[0]}; repair the mesh")
    return mesh
