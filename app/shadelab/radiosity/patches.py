"""The scene's surfaces cut into radiosity patches: regular grids, refined where B changes fast.

Quads and planes are *surfaces* meshed by a quadtree over their (u, v) parameter square: a
regular base grid of about the target patch size, whose cells (leaves) can be split into four
where the radiosity changes fast (shadow boundaries, corners), so that flat regions stay
coarse. Leaves are stored in integer coordinates at the finest level (``FINE`` units per base
cell), which lets the display find T-vertices exactly. Any other shape (spheres, boxes, mesh
files) keeps its triangles, each cut regularly into k x k smaller ones with the same k over the
whole object, which is conforming by construction. When keeping one patch per triangle would
exceed the budget (a 100k-triangle scan on a floor), the mesh objects are *clustered* instead:
vertex clustering on a spatial grid (Rossignac & Borrel 1993) merges the vertices of each grid
cell into their mean, so each patch is one triangle of the coarser mesh standing for the
original triangles around it; the grid is the finest that keeps the object within its share
of the budget (:func:`cluster_mesh`), so the patch count never exceeds ``count``.

Every patch is stored as a 4-corner polygon (a triangle repeats its last corner), counter-
clockwise seen from the front: the form factors, the hemicube and the display read one layout.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from shadelab.errors import ShadeLabError
from shadelab.geometry.mesh import scene_meshes
from shadelab.scene.model import Scene
from shadelab.shading.packing import reflectance

MAX_LEVEL = 6  # quadtree depth below the base grid
CLUSTER_ROUNDS = 40  # bisection steps on the clustering grid's cell size
MESH_SHARE = 0.5  # clustered meshes share at least this part of the budget (the rest by area)
FINE = 1 << MAX_LEVEL  # integer units per base cell edge


@dataclass
class Surface:
    """One object's meshing domain.

    Attributes
    ----------
    kind : "quad" (bilinear quadtree) or "mesh" (regularly split triangles)
    corners : (4, 3) float64 world corners of a quad surface, counter-clockwise from the front
    grid : (nu, nv) base cells of a quad surface
    vertices, faces : the split triangles of a mesh surface (world space)
    """

    object_index: int
    material: str
    kind: str
    corners: np.ndarray | None = None
    grid: tuple[int, int] = (1, 1)
    vertices: np.ndarray | None = None
    faces: np.ndarray | None = None
    original: tuple | None = None  # a clustered mesh's own (vertices, faces, and each
    #                                vertex's clustered vertex): the display draws these


    def point(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """World points of integer quadtree coordinates (x along u, y along v)."""
        u = np.asarray(x, float) / (self.grid[0] * FINE)
        v = np.asarray(y, float) / (self.grid[1] * FINE)
        p0, p1, p2, p3 = self.corners
        return (((1 - u) * (1 - v))[..., None] * p0 + (u * (1 - v))[..., None] * p1
                + (u * v)[..., None] * p2 + ((1 - u) * v)[..., None] * p3)


@dataclass
class PatchSet:
    """Patches of a scene, the unknowns of the radiosity system.

    Attributes
    ----------
    polygons : (N, 4, 3) float64 world corners, counter-clockwise from the front
    normals : (N, 3) unit; areas : (N,) world units squared; centers : (N, 3)
    rho : (N, 3) reflectance kd * Od; emission : (N, 3) emitted radiance Le (E = pi * Le)
    surface : (N,) index into ``surfaces``
    rects : (N, 4) int quadtree leaf (x0, y0, x1, y1) on quad surfaces, -1 elsewhere
    tri : (N, 3) int vertex indices into the surface's vertices on mesh surfaces, -1 elsewhere
    """

    surfaces: list[Surface]
    polygons: np.ndarray
    normals: np.ndarray
    areas: np.ndarray
    centers: np.ndarray
    rho: np.ndarray
    emission: np.ndarray
    surface: np.ndarray
    rects: np.ndarray
    tri: np.ndarray
    info: dict = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.areas)

    @property
    def E(self) -> np.ndarray:
        """(N, 3) emitted radiosity, pi * Le."""
        return math.pi * self.emission


def check_count(count: int, key: str = "--patches") -> int:
    if not isinstance(count, (int, np.integer)) or isinstance(count, bool) or count < 1:
        raise ShadeLabError(f"{key} {count!r}: expected a patch count >= 1")
    return int(count)


def polygon_area_normal(poly: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Areas (N,) and unit normals (N, 3) of (N, 4, 3) planar polygons (Newell's vector)."""
    cross = np.zeros(poly.shape[:-2] + (3,))
    for k in range(4):
        cross += np.cross(poly[..., k, :], poly[..., (k + 1) % 4, :])
    length = np.linalg.norm(cross, axis=-1)
    return 0.5 * length, cross / np.maximum(length, 1e-300)[..., None]


def scene_surfaces(scene: Scene) -> list[Surface]:
    """One meshing surface per object: quads and planes by their corners, the rest as triangles."""
    surfaces = []
    for mesh, obj in zip(scene_meshes(scene), scene.objects, strict=True):
        if obj.shape in ("quad", "plane"):
            s = obj.segments
            corners = mesh.vertices[[0, s, (s + 1) ** 2 - 1, (s + 1) * s]]
            surfaces.append(Surface(mesh.index, obj.material, "quad", corners=corners.copy()))
        else:
            surfaces.append(Surface(mesh.index, obj.material, "mesh",
                                    vertices=np.asarray(mesh.vertices, float),
                                    faces=np.asarray(mesh.faces, np.int64)))
    return surfaces


def _quad_grid(corners: np.ndarray, h: float) -> tuple[int, int]:
    """Base cells along u and v so that cells are about h wide."""
    p0, p1, p2, p3 = corners
    lu = 0.5 * (np.linalg.norm(p1 - p0) + np.linalg.norm(p2 - p3))
    lv = 0.5 * (np.linalg.norm(p3 - p0) + np.linalg.norm(p2 - p1))
    return max(1, int(round(lu / h))), max(1, int(round(lv / h)))


def _mesh_split(vertices: np.ndarray, faces: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Cut each triangle into k*k; shared edges are cut the same way, vertices merged."""
    if k <= 1:
        return vertices, faces
    points, tris = [], []
    for a, b, c in vertices[faces]:
        base = len(points)
        index = {}
        for i in range(k + 1):
            for j in range(k + 1 - i):
                index[i, j] = base + len(index)
                points.append(a + (b - a) * (i / k) + (c - a) * (j / k))
        for i in range(k):
            for j in range(k - i):
                tris.append((index[i, j], index[i + 1, j], index[i, j + 1]))
                if i + j < k - 1:
                    tris.append((index[i + 1, j], index[i + 1, j + 1], index[i, j + 1]))
    points = np.asarray(points)
    scale = max(float(np.ptp(points, axis=0).max()), 1e-12)
    keys = np.round(points / (scale * 1e-9)).astype(np.int64)
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    return points[first], inverse.reshape(-1)[np.asarray(tris)]


def _surface_area(surface: Surface) -> float:
    if surface.kind == "quad":
        return float(polygon_area_normal(surface.corners[None])[0][0])
    tri = surface.vertices[surface.faces]
    return float(0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]),
                                      axis=1).sum())


def _count_for(surfaces: list[Surface], h: float) -> int:
    total = 0
    for s in surfaces:
        if s.kind == "quad":
            nu, nv = _quad_grid(s.corners, h)
            total += nu * nv
        else:
            per = _surface_area(s) / max(len(s.faces), 1)
            total += len(s.faces) * max(1, int(round(math.sqrt(per) / h))) ** 2
    return total


def cluster_mesh(vertices: np.ndarray, faces: np.ndarray, target: int,
                 vertex_map: bool = False):
    """At most ``target`` triangles standing for ``faces``: vertex clustering on the finest
    regular grid (bisection on its cell size) that leaves no more; each cell's vertices merge
    into their mean, collapsed and repeated triangles go. The input when it already fits.

    Returns (vertices, faces); with ``vertex_map`` also (V_in,) the clustered vertex each
    input vertex merged into (the nearest one where its cell's triangles all collapsed)."""
    vertices = np.asarray(vertices, float)
    faces = np.asarray(faces, np.int64)
    target = max(1, int(target))
    if len(faces) <= target:
        return (vertices, faces, np.arange(len(vertices))) if vertex_map else (vertices, faces)
    lo_corner = vertices.min(axis=0)
    extent = max(float(np.ptp(vertices, axis=0).max()), 1e-12)

    def clustered(cell: float):
        cells = np.floor((vertices - lo_corner) / cell).astype(np.int64)
        side = int(cells.max()) + 1
        keys = (cells[:, 0] * side + cells[:, 1]) * side + cells[:, 2]
        _, inverse = np.unique(keys, return_inverse=True)
        inverse = inverse.reshape(-1)
        counts = np.bincount(inverse)
        merged = np.zeros((len(counts), 3))
        np.add.at(merged, inverse, vertices)
        merged /= counts[:, None]
        f = inverse[faces]
        f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])]
        if len(f):
            g = np.sort(f, axis=1)
            n = int(g.max()) + 1
            _, first = np.unique((g[:, 0] * n + g[:, 1]) * n + g[:, 2], return_index=True)
            f = f[np.sort(first)]
            tri = merged[f]
            area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
            f = f[area > 1e-12 * extent * extent]
        used, f = np.unique(f, return_inverse=True)
        return merged[used], f.reshape(-1, 3), (used, inverse)

    lo = extent / max(math.sqrt(target), 1.0) / 16.0  # fine enough to keep > target
    hi = extent * 1.01  # one cell: no triangle left
    best = clustered(hi)
    for _ in range(CLUSTER_ROUNDS):
        mid = math.sqrt(lo * hi)
        v, f, cells = clustered(mid)
        if len(f) <= target:
            hi, best = mid, (v, f, cells)
        else:
            lo = mid
        if hi / lo < 1.01:
            break
    v, f, (used, inverse) = best
    if not vertex_map:
        return v, f
    if len(used) == 0:  # every triangle collapsed: nothing to draw
        return v, f, np.zeros(len(vertices), np.int64)
    where = np.searchsorted(used, inverse)
    found = (where < len(used)) & (used[np.minimum(where, len(used) - 1)] == inverse)
    out = np.where(found, where, -1)
    if (~found).any() and len(v):
        from scipy.spatial import cKDTree

        out[~found] = cKDTree(v).query(vertices[~found])[1]
    return v, f, np.maximum(out, 0)


def _cluster_targets(surfaces: list[Surface], count: int) -> dict[int, int]:
    """Per mesh surface (index): its patch budget when meshes must be clustered: its area
    share of ``count``, at least an equal part of ``MESH_SHARE`` of it."""
    mesh = [i for i, s in enumerate(surfaces) if s.kind == "mesh"]
    total = sum(_surface_area(s) for s in surfaces)
    floor_share = max(1, int(MESH_SHARE * count) // max(len(mesh), 1))
    targets = {i: min(len(surfaces[i].faces),
                      max(floor_share, int(count * _surface_area(surfaces[i]) / total)))
               for i in mesh}
    room = count - sum(1 for s in surfaces if s.kind == "quad")  # a quad keeps one cell
    scale = min(1.0, room / max(sum(targets.values()), 1))
    return {i: max(1, int(t * scale)) for i, t in targets.items()}


def _quad_count(surfaces: list[Surface], h: float) -> int:
    return sum(int(np.prod(_quad_grid(s.corners, h))) for s in surfaces if s.kind == "quad")


def uniform_patches(scene: Scene, count: int) -> PatchSet:
    """A regular meshing with about ``count`` patches of equal size (no refinement); mesh
    objects whose triangles alone would exceed ``count`` are clustered, and then the patch
    count is at most ``count`` (see the module docstring)."""
    count = check_count(count)
    surfaces = scene_surfaces(scene)
    if not surfaces:
        raise ShadeLabError("objects: the scene has no surfaces to mesh into patches")
    if needs_clustering(surfaces, count):
        return _clustered_patches(scene, surfaces, count)
    total = sum(_surface_area(s) for s in surfaces)
    # Find the patch size h whose meshing comes closest to the target count (bisection on log h)
    # (capped near the mean patch size, so that mesh objects, which keep one patch per
    # triangle at least, do not leave the quads a single patch each)
    lo, hi = math.sqrt(total / count) / 8.0, math.sqrt(total / count) * 1.5
    for _ in range(40):
        mid = math.sqrt(lo * hi)
        if _count_for(surfaces, mid) > count:
            lo = mid
        else:
            hi = mid
    # Counts jump as grids gain a row: take the side of the jump closer to the target
    h = lo if abs(_count_for(surfaces, lo) - count) < abs(_count_for(surfaces, hi) - count) \
        else hi
    leaves = []
    for index, s in enumerate(surfaces):
        if s.kind == "quad":
            s.grid = _quad_grid(s.corners, h)
            for i in range(s.grid[0]):
                for j in range(s.grid[1]):
                    leaves.append((index, i * FINE, j * FINE, (i + 1) * FINE, (j + 1) * FINE))
        else:
            per = _surface_area(s) / max(len(s.faces), 1)
            k = max(1, int(round(math.sqrt(per) / h)))
            s.vertices, s.faces = _mesh_split(s.vertices, s.faces, k)
    return assemble(scene, surfaces, leaves)


def needs_clustering(surfaces: list[Surface], count: int) -> bool:
    """Would one patch per mesh triangle (and one cell per quad) exceed ``count``?"""
    mesh_faces = sum(len(s.faces) for s in surfaces if s.kind == "mesh")
    quads = sum(1 for s in surfaces if s.kind == "quad")
    return bool(mesh_faces) and mesh_faces + quads > count


def cluster_surfaces(surfaces: list[Surface], count: int) -> int:
    """Cluster every mesh surface (in place) to its share of ``count``
    (:func:`_cluster_targets`); returns the patches left to the quads."""
    targets = _cluster_targets(surfaces, count)
    for index, target in targets.items():
        s = surfaces[index]
        vertices, faces = s.vertices, s.faces
        s.vertices, s.faces, to_cluster = cluster_mesh(vertices, faces, target, vertex_map=True)
        if len(s.faces) < len(faces):
            s.original = (vertices, faces, to_cluster)
    return count - sum(len(surfaces[i].faces) for i in targets)


def quad_leaves(surfaces: list[Surface], rest: int) -> list[tuple]:
    """The regular grid of the coarsest cell size h with at most ``rest`` quad cells (at
    least one each): sets each quad surface's ``grid``, returns its leaves."""
    quad_area = sum(_surface_area(s) for s in surfaces if s.kind == "quad")
    leaves: list[tuple] = []
    if quad_area <= 0.0:
        return leaves
    lo = math.sqrt(quad_area / max(rest, 1)) / 8.0
    hi = max(math.sqrt(quad_area / max(rest, 1)) * 4.0,
             max(float(np.ptp(s.corners, axis=0).max()) for s in surfaces
                 if s.kind == "quad") * 2.0)
    for _ in range(40):
        mid = math.sqrt(lo * hi)
        if _quad_count(surfaces, mid) > rest:
            lo = mid
        else:
            hi = mid
    for index, s in enumerate(surfaces):
        if s.kind != "quad":
            continue
        s.grid = _quad_grid(s.corners, hi)
        for i in range(s.grid[0]):
            for j in range(s.grid[1]):
                leaves.append((index, i * FINE, j * FINE, (i + 1) * FINE, (j + 1) * FINE))
    return leaves


def _clustered_patches(scene: Scene, surfaces: list[Surface], count: int) -> PatchSet:
    """Meshes clustered to their share of ``count`` (:func:`_cluster_targets`), quads on the
    regular grid of the coarsest size h that fits the rest (at least one cell each)."""
    import time

    start = time.perf_counter()
    triangles_in = sum(len(s.faces) for s in surfaces if s.kind == "mesh")
    rest = cluster_surfaces(surfaces, count)
    patches = assemble(scene, surfaces, quad_leaves(surfaces, rest))
    patches.info.update(clustered=True, clustering_s=time.perf_counter() - start,
                        mesh_triangles=triangles_in)
    return patches


def assemble(scene: Scene, surfaces: list[Surface], leaves: list[tuple]) -> PatchSet:
    """Build the patch arrays from quad leaves plus every mesh surface's triangles."""
    polygons, surface_of, rects, tris = [], [], [], []
    if len(leaves):
        table = np.asarray(leaves, np.int64).reshape(-1, 5)
        polygons = list(leaf_corners(surfaces, table))
        surface_of = list(table[:, 0])
        rects = [tuple(r) for r in table[:, 1:]]
        tris = [(-1, -1, -1)] * len(table)
    for index, s in enumerate(surfaces):
        if s.kind != "mesh":
            continue
        for face in s.faces:
            polygons.append(s.vertices[[face[0], face[1], face[2], face[2]]])
            surface_of.append(index)
            rects.append((-1, -1, -1, -1))
            tris.append(tuple(face))
    polygons = np.asarray(polygons, float).reshape(-1, 4, 3)
    areas, normals = polygon_area_normal(polygons)
    surface_of = np.asarray(surface_of, np.int64)
    rho = np.zeros((len(areas), 3))
    emission = np.zeros((len(areas), 3))
    for index, s in enumerate(surfaces):
        material = scene.materials[s.material]
        mask = surface_of == index
        rho[mask] = reflectance(material)
        emission[mask] = material.emission
    keep = areas > 1e-12 * max(float(areas.max(initial=0.0)), 1e-300)
    centers = (polygons * _corner_weights(polygons)[..., None]).sum(axis=1)
    patches = PatchSet(surfaces, polygons[keep], normals[keep], areas[keep], centers[keep],
                       rho[keep], emission[keep], surface_of[keep],
                       np.asarray(rects, np.int64).reshape(-1, 4)[keep],
                       np.asarray(tris, np.int64).reshape(-1, 3)[keep])
    patches.info["patches"] = len(patches)
    check_made(len(patches))
    return patches


def check_made(made: int) -> None:
    """The patch limit (:data:`shadelab.limits.MAX_PATCHES`) on the patches really made."""
    from shadelab import limits

    limits.check(f"radiosity: {made} patches made", made, limits.MAX_PATCHES, "patches",
                 8.0 * made * made)


def leaf_corners(surfaces: list[Surface], table: np.ndarray) -> np.ndarray:
    """(L, 4, 3) world corners of quadtree leaves, rows (surface, x0, y0, x1, y1)."""
    out = np.zeros((len(table), 4, 3))
    for index in np.unique(table[:, 0]):
        rows = np.flatnonzero(table[:, 0] == index)
        x0, y0, x1, y1 = (table[rows, k + 1] for k in range(4))
        out[rows] = surfaces[int(index)].point(np.stack([x0, x1, x1, x0], axis=1),
                                               np.stack([y0, y0, y1, y1], axis=1))
    return out


def _corner_weights(polygons: np.ndarray) -> np.ndarray:
    """Weights giving the area centroid of each polygon from its 4 corners (two triangles)."""
    a0 = 0.5 * np.linalg.norm(np.cross(polygons[:, 1] - polygons[:, 0],
                                       polygons[:, 2] - polygons[:, 0]), axis=1)
    a1 = 0.5 * np.linalg.norm(np.cross(polygons[:, 2] - polygons[:, 0],
                                       polygons[:, 3] - polygons[:, 0]), axis=1)
    total = np.maximum(a0 + a1, 1e-300)
    w = np.zeros((len(polygons), 4))
    w[:, [0, 1, 2]] += (a0 / total / 3.0)[:, None]
    w[:, [0, 2, 3]] += (a1 / total / 3.0)[:, None]
    return w


def leaves_of(patches: PatchSet) -> list[tuple]:
    """The quad leaves (surface, x0, y0, x1, y1) of a patch set."""
    quad = patches.rects[:, 0] >= 0
    pairs = zip(patches.surface[quad], patches.rects[quad], strict=True)
    return [(int(s), *map(int, r)) for s, r in pairs]


def split_leaves(scene: Scene, patches: PatchSet, chosen: np.ndarray) -> PatchSet:
    """Split the chosen quad patches (indices) into four children each."""
    chosen = set(int(i) for i in chosen)
    leaves = []
    for i in np.flatnonzero(patches.rects[:, 0] >= 0):
        s = int(patches.surface[i])
        x0, y0, x1, y1 = map(int, patches.rects[i])
        if i in chosen and x1 - x0 > 1:
            xm, ym = (x0 + x1) // 2, (y0 + y1) // 2
            leaves += [(s, x0, y0, xm, ym), (s, xm, y0, x1, ym), (s, xm, ym, x1, y1),
                       (s, x0, ym, xm, y1)]
        else:
            leaves.append((s, x0, y0, x1, y1))
    return assemble(scene, patches.surfaces, leaves)


def from_polygons(polygons, rho=0.0, emission=0.0) -> PatchSet:
    """A patch set straight from (N, 4, 3) or (N, 3, 3) polygons (tests, teaching examples).

    ``rho`` and ``emission`` broadcast to (N, 3).
    """
    polygons = np.asarray(polygons, float)
    if polygons.shape[1] == 3:
        polygons = polygons[:, [0, 1, 2, 2]]
    n = len(polygons)
    areas, normals = polygon_area_normal(polygons)
    centers = (polygons * _corner_weights(polygons)[..., None]).sum(axis=1)
    rho = np.broadcast_to(np.asarray(rho, float).reshape(-1, 1) if np.ndim(rho) == 1
                          and len(rho) == n else np.asarray(rho, float), (n, 3)).copy()
    emission = np.broadcast_to(np.asarray(emission, float).reshape(-1, 1)
                               if np.ndim(emission) == 1 and len(emission) == n
                               else np.asarray(emission, float), (n, 3)).copy()
    return PatchSet([], polygons, normals, areas, centers, rho, emission,
                    np.zeros(n, np.int64), np.full((n, 4), -1, np.int64),
                    np.full((n, 3), -1, np.int64), {"patches": n})
