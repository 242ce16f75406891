"""Scene objects to world-space triangle meshes (trimesh primitives or mesh files).

Every renderer reads the same :class:`MeshData`, so raster, ray-traced and radiosity images
show the same triangles.
"""

from __future__ import annotations

import copy
import math
import os
import re
import sys
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from pathlib import Path

import numpy as np
from pyrr import matrix33

from shadelab import limits
from shadelab.errors import ShadeLabError
from shadelab.geometry import cache
from shadelab.geometry.normals import (
    corner_normals,
    face_areas,
    face_normals,
    flipped_corners,
    terminator_threshold,
    vertex_terminators,
)
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

    @cached_property
    def corner_terminators(self) -> np.ndarray:
        """(F, 3) the terminator threshold t_v at each corner (:func:`vertex_terminators`),
        the ``in_terminator`` vertex attribute of the shadow-volume lit pass; notes once
        when some corner normals lean more than 90 degrees from their face (left out)."""
        flipped = flipped_corners(self.face_normals, self.corner_normals)
        if flipped:
            note(f"objects.{self.index}: {flipped} corner normal(s) lean more than 90 degrees "
                 f"from their face; the shadow terminator fade leaves them out")
        return vertex_terminators(self.vertices, self.faces, self.face_normals,
                                  self.corner_normals)


def geometry_key(obj: Object, base_dir: str) -> tuple:
    """Everything that changes an object's triangles (not its material)."""
    return (obj.shape, obj.path, base_dir, obj.radius, obj.minor_radius, obj.height,
            tuple(obj.extents), obj.size, tuple(map(tuple, obj.vertices)), obj.subdivisions,
            obj.sections, obj.segments, tuple(obj.translate), tuple(obj.rotate),
            tuple(obj.scale), obj.normals, obj.crease_angle, obj.weld)


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
    vertices, faces, uvs, places = _local_mesh(obj, key[2], index)
    matrix = world_from_object(obj)
    vertices = vertices @ matrix[:3, :3].T + matrix[:3, 3]
    if np.linalg.det(matrix[:3, :3]) < 0.0:  # a mirroring scale flips the winding back
        faces = faces[:, ::-1].copy()
    fn = face_normals(vertices, faces)
    parts = () if places is None else (places,)
    name = cache.key("normals", vertices, faces, obj.normals, obj.crease_angle, *parts)
    hit = cache.load(name)
    if hit is not None and hit.get("corner_normals", np.empty(0)).shape == (len(faces), 3, 3):
        cn = hit["corner_normals"]
    else:
        # Welded mesh files: corners at one place share their normal even where a uv seam
        # keeps two vertices (the normals see the welded surface, the texture its seams).
        first = np.zeros(0, np.int64) if places is None else \
            np.unique(places, return_index=True)[1]
        at, by = (vertices, faces) if places is None else (vertices[first], places[faces])
        with busy(f"objects.{index}: {len(faces)} triangles' normals"):
            cn = corner_normals(at, by, obj.normals, obj.crease_angle,
                                progress=_triangle_bar(len(faces), f"objects.{index}: normals"))
        cache.store(name, {"corner_normals": cn})
    for array in (vertices, faces, uvs, fn, cn):
        array.setflags(write=False)
    return vertices, faces, uvs, fn, cn


def _object_from_key(key: tuple) -> Object:
    (shape, path, _base, radius, minor, height, extents, size, vertices, subdivisions, sections,
     segments, translate, rotate, scale, normals, crease, weld) = key
    return Object(shape=shape, path=path, radius=radius, minor_radius=minor, height=height,
                  extents=extents, size=size, vertices=[list(v) for v in vertices],
                  subdivisions=subdivisions, sections=sections, segments=segments,
                  translate=translate, rotate=rotate, scale=scale, normals=normals,
                  crease_angle=crease, weld=weld)


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
    """(vertices, faces, uvs, places): places maps each vertex to its welded position
    (mesh files loaded with weld; None otherwise)."""
    if shape == "quad":
        return (*grid(np.asarray(obj.vertices, dtype=np.float64), obj.segments), None)
    if shape == "plane":
        h = obj.size / 2.0
        corners = np.array([[-h, 0, h], [h, 0, h], [h, 0, -h], [-h, 0, -h]])
        return (*grid(corners, obj.segments), None)
    if shape == "mesh":
        mesh = read_mesh(obj.path, base_dir, f"objects.{index}.path", weld=obj.weld)
        uvs = mesh.uvs if mesh.uvs is not None else _projected_uvs(mesh.vertices, shape)
        return mesh.vertices, mesh.faces, uvs, mesh.places
    name = cache.key("primitive", shape, obj.radius, obj.minor_radius, obj.height,
                     tuple(obj.extents), obj.subdivisions, obj.sections)
    hit = cache.load(name)
    if _sound(hit):
        vertices, faces = hit["vertices"], hit["faces"]
    else:
        vertices, faces = _primitive(obj, index)
        cache.store(name, {"vertices": vertices, "faces": faces})
    return vertices, faces, _projected_uvs(vertices, shape), None


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
    """Load a mesh file, refusing what no renderer can use, with a one-line reason.

    Returns the trimesh as read (unwelded, degenerate triangles kept); a file whose every
    triangle is degenerate is refused here (see :func:`read_mesh` for what renderers draw).
    """
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

    options = {"skip_materials": True} if full.suffix.lower() == ".obj" else {}
    try:
        with busy(f"{key}: reading '{full.name}'"):
            mesh = trimesh.load(str(full), force="mesh", process=False, **options)
    except Exception as exc:  # trimesh raises many types for corrupt files
        raise ShadeLabError(f"{key}: '{full.name}' could not be read as a mesh ({exc})") from None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise ShadeLabError(f"{key}: '{full.name}' holds no triangles (empty mesh)")
    check_vertices(np.asarray(mesh.vertices, dtype=np.float64), f"{key}: '{full.name}'")
    limits.check(f"{key}: '{full.name}'", len(mesh.faces), limits.MAX_TRIANGLES, "triangles",
                 memory_bytes=400.0 * len(mesh.faces))  # normals, BVH, GL buffers
    areas = face_areas(np.asarray(mesh.vertices, float), np.asarray(mesh.faces))
    if not (areas > DEGENERATE_AREA * max(float(areas.max()), 1e-300)).any() \
            or float(areas.max()) == 0.0:
        raise ShadeLabError(f"{key}: '{full.name}' has only degenerate (zero-area) triangles "
                            f"({len(areas)} of them): nothing to draw")
    return mesh


# ---------------------------------------------------------------- what renderers draw

DEGENERATE_AREA = 1e-12     # a triangle under this fraction of the largest one has no area
WELD_TOLERANCE = 1e-6       # welding distance, a fraction of the bounding-box diagonal
UV_TOLERANCE = 1e-6         # texture coordinates closer than this are one


@dataclass
class LoadedMesh:
    """A mesh file as renderers draw it (object space).

    vertices (V, 3) float64; faces (F, 3) int64 with no zero-area triangle; uvs (V, 2) from
    the file or None; places (V,) int64, the welded position of each vertex where a uv seam
    keeps two vertices at one place (None when every vertex is its own place); dropped: the
    zero-area triangles left out."""

    vertices: np.ndarray
    faces: np.ndarray
    uvs: np.ndarray | None
    places: np.ndarray | None
    dropped: int = 0


def weld_vertices(vertices: np.ndarray, faces: np.ndarray, uvs: np.ndarray | None = None,
         tolerance: float | None = None):
    """Merge vertices closer than ``tolerance`` (default WELD_TOLERANCE of the bounding-box
    diagonal; positions are snapped to a grid of that step) that also share their uv.

    Returns (vertices, faces, uvs, places): places (V,) numbers the distinct positions, so
    vertices split only by a uv seam share a place (None when no seam splits any).
    """
    if tolerance is None:
        diagonal = float(np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0)))
        tolerance = WELD_TOLERANCE * diagonal
    if tolerance <= 0.0:
        tolerance = 1e-300
    snapped = np.round((vertices - vertices.min(axis=0)) / tolerance).astype(np.int64)
    _, place = np.unique(snapped, axis=0, return_inverse=True)
    place = place.reshape(-1)
    if uvs is None:
        keys = place[:, None]
    else:
        keys = np.column_stack([place, np.round(uvs / UV_TOLERANCE).astype(np.int64)])
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    new_faces = inverse[faces]
    new_uvs = None if uvs is None else uvs[first]
    places = place[first]
    if len(np.unique(places)) == len(places):
        places = None
    else:
        places = np.unique(places, return_inverse=True)[1].reshape(-1).astype(np.int64)
    return vertices[first], new_faces.astype(np.int64), new_uvs, places


def drop_degenerate(vertices: np.ndarray, faces: np.ndarray,
                    places: np.ndarray | None = None) -> tuple[np.ndarray, int]:
    """Faces with no area (two corners at one vertex or place, or area under DEGENERATE_AREA
    of the largest) left out: (kept faces, how many were dropped)."""
    corners = faces if places is None else places[faces]
    areas = face_areas(vertices, faces)
    keep = ((corners[:, 0] != corners[:, 1]) & (corners[:, 1] != corners[:, 2])
            & (corners[:, 2] != corners[:, 0])
            & (areas > DEGENERATE_AREA * max(float(areas.max(initial=0.0)), 1e-300)))
    return faces[keep], int(len(faces) - keep.sum())


_NOTED: set[str] = set()


def note(message: str) -> None:
    """One line on stderr, once per message and process (what was dropped or ignored)."""
    if message in _NOTED:
        return
    _NOTED.add(message)
    print(f"shadelab: note: {message}", file=sys.stderr, flush=True)


def read_mesh(path: str, base_dir: str, key: str, weld: bool = True) -> LoadedMesh:
    """A mesh file's triangles for the renderers: welded (unless ``weld`` is False), its
    zero-area triangles dropped with a one-line note; refused only when none is left."""
    mesh = load_mesh_file(path, base_dir, key)
    name = Path(path).name
    vertices = np.asarray(mesh.vertices, dtype=np.float64)
    faces = np.asarray(mesh.faces, dtype=np.int64)
    uv = getattr(mesh.visual, "uv", None)
    uvs = None
    if uv is not None and len(uv) == len(vertices):
        uvs = np.asarray(uv, dtype=np.float64)
        if not np.isfinite(uvs).all():
            uvs = None
    places = None
    if weld:
        vertices, faces, uvs, places = weld_vertices(vertices, faces, uvs)
    faces, dropped = drop_degenerate(vertices, faces, places)
    check_fans(faces, places, f"{key}: '{name}'")
    if len(faces) == 0:
        raise ShadeLabError(f"{key}: '{name}' has only degenerate (zero-area) triangles "
                            f"({dropped} of them): nothing to draw")
    if dropped:
        note(f"{key}: '{name}': dropped {dropped} degenerate (zero-area) "
             f"triangle{'s' if dropped != 1 else ''} of {dropped + len(faces)}")
    return LoadedMesh(vertices, faces, uvs, places, dropped)


def check_fans(faces: np.ndarray, places: np.ndarray | None, where: str) -> None:
    """The triangles around one vertex stay within limits.MAX_VERTEX_FACES: a polygon of
    100,000 vertices (fanned into triangles from one corner) or one face repeated 300,000
    times would ask the normals for a k x k comparison (74 GiB, 671 GiB)."""
    if len(faces) == 0:
        return
    at = places[faces] if places is not None else faces
    counts = np.bincount(at.reshape(-1))
    vertex = int(counts.argmax())
    k = int(counts[vertex])
    what = f"{where}: vertex {vertex} is a corner of {k:,} triangles (a huge polygon's fan " \
        "or repeated faces)"
    limits.check(what, k, limits.MAX_VERTEX_FACES, " triangles at a vertex")  # the budget
    limits.check(what, k, float("inf"), " triangles at a vertex", memory_bytes=9.0 * k * k)


TRIANGLE_BAR_MIN = 200_000  # a mesh this large shows a bar (in triangles) on a terminal


def _triangle_bar(total: int, desc: str):
    """A callback ``done(triangles)`` that moves a tqdm bar counted in triangles (CLI on a
    terminal, meshes of TRIANGLE_BAR_MIN triangles or more; see shadelab.progress), else
    None."""
    from shadelab import progress

    if not progress.SHOW_STEPS or total < TRIANGLE_BAR_MIN:
        return None
    from tqdm import tqdm

    bar = tqdm(total=total, desc=desc, unit="tri", unit_scale=True, leave=False,
               delay=progress.STEP_DELAY_S, mininterval=0.5, dynamic_ncols=True)

    def done(triangles: int) -> None:
        bar.update(triangles)
        if bar.n >= total:
            bar.close()

    return done


# ---------------------------------------------------------------- an OBJ's material (MTL)

MTL_USED = ("newmtl", "Kd", "map_Kd")


@dataclass
class ObjMaterial:
    """The first material an OBJ file uses, from its MTL: ``kd`` (or None), ``map_kd`` the
    texture file (resolved beside the MTL, or None), ``ignored`` what ShadeLab does not use."""

    name: str
    mtl: Path
    kd: tuple[float, float, float] | None = None
    map_kd: Path | None = None
    ignored: list[str] = field(default_factory=list)


_OBJ_MTL = re.compile(rb"^[ \t]*(mtllib|usemtl)[ \t]+([^\r\n#]*)", re.MULTILINE)


def obj_material(full: Path, key: str) -> ObjMaterial | None:
    """The material an OBJ file names (``mtllib`` + first ``usemtl``), or None when it names
    none; an MTL that cannot be read is a one-line note and None, not an error."""
    try:
        data = full.read_bytes()
    except OSError:
        return None  # load_mesh_file reports the file itself
    libraries, used = [], []
    for word, value in _OBJ_MTL.findall(data):
        text = value.decode("utf-8", "replace").strip()
        if text:
            (libraries if word == b"mtllib" else used).append(text)
    if not libraries:
        return None
    mtl = full.parent / libraries[0].replace("\\", "/")
    problem = file_problem(mtl)
    if problem:
        note(f"{key}: '{full.name}' names material library '{libraries[0]}', which {problem}; "
             f"its colours are ignored")
        return None
    try:
        text = mtl.read_bytes().decode("utf-8", "replace")
    except OSError as exc:
        note(f"{key}: '{mtl.name}' could not be read ({exc.strerror}); its colours are ignored")
        return None
    tables: dict[str, dict[str, str]] = {}
    current = None
    for line in text.splitlines():
        parts = line.split("#", 1)[0].split(None, 1)
        if not parts:
            continue
        word, rest = parts[0], (parts[1].strip() if len(parts) > 1 else "")
        if word == "newmtl":
            current = tables.setdefault(rest, {})
        elif current is not None:
            current[word] = rest
    distinct = list(dict.fromkeys(used))
    name = distinct[0] if distinct else next(iter(tables), "")
    if name not in tables:
        note(f"{key}: '{mtl.name}' has no material '{name}'; its colours are ignored")
        return None
    table = tables[name]
    out = ObjMaterial(name, mtl)
    if "Kd" in table:
        try:
            kd = [float(v) for v in table["Kd"].split()[:3]]
            if len(kd) == 3 and all(math.isfinite(v) for v in kd):
                out.kd = tuple(min(max(v, 0.0), 1.0) for v in kd)
        except ValueError:
            pass
        if out.kd is None:
            out.ignored.append(f"Kd '{table['Kd']}' (expected three numbers)")
    if table.get("map_Kd"):
        # options (-s 1 1 1, -clamp on, ...) come first; the file name is the last word
        out.map_kd = mtl.parent / table["map_Kd"].split()[-1].replace("\\", "/")
    out.ignored += sorted(k for k in table if k not in MTL_USED)
    if len(distinct) > 1:
        out.ignored.append(f"materials {', '.join(distinct[1:])} (one material per object)")
    return out


def adopt_obj_materials(scene: Scene, given: dict[str, set[str]], source: str) -> None:
    """Each OBJ object's MTL ``Kd`` and ``map_Kd`` as its material's ``Od`` and ``texture``
    (at ``texture_scale`` 1, the file's own uvs) where the preset sets none of them
    (``given``: the keys each preset material table sets). The object gets a copy of its
    material named ``<material>-<file stem>``; what the MTL holds beyond them is named once
    in one line. A texture file that is not there is a one-line error."""
    for i, obj in enumerate(scene.objects):
        if obj.shape != "mesh" or Path(obj.path).suffix.lower() != ".obj":
            continue
        key = f"objects.{i}.path"
        full = Path(obj.path) if Path(obj.path).is_absolute() else Path(scene.base_dir) / obj.path
        info = obj_material(full, key)
        if info is None:
            continue
        keys = given.get(obj.material, set())
        changes: dict = {}
        ignored = list(info.ignored)
        if info.map_kd is not None:
            if "texture" in keys:
                ignored.append("map_Kd (the preset sets a texture)")
            else:
                problem = file_problem(info.map_kd)
                if problem:
                    raise ShadeLabError(f"{source}: key '{key}': '{info.mtl.name}' names texture "
                                        f"map_Kd '{info.map_kd.name}', which {problem}")
                changes["texture"] = _relative(info.map_kd, Path(scene.base_dir))
                if "texture_scale" not in keys:
                    changes["texture_scale"] = 1.0
        if info.kd is not None:
            if "Od" in keys:
                ignored.append("Kd (the preset sets Od)")
            else:
                changes["Od"] = info.kd
        if ignored:
            note(f"{key}: '{info.mtl.name}' material '{info.name}': ignored {', '.join(ignored)}")
        if not changes:
            continue
        material = copy.deepcopy(scene.materials[obj.material])
        for name, value in changes.items():
            setattr(material, name, value)
        base = f"{obj.material}-{full.stem}"
        name, n = base, 2
        while name in scene.materials and scene.materials[name] != material:
            name, n = f"{base}-{n}", n + 1
        scene.materials[name] = material
        obj.material = name


def _relative(path: Path, base: Path) -> str:
    """``path`` relative to ``base`` where it can be (POSIX separators), else absolute."""
    try:
        return Path(os.path.relpath(path.resolve(), base.resolve())).as_posix()
    except ValueError:  # another drive
        return str(path.resolve())
