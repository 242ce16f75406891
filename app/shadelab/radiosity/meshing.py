"""Discontinuity meshing: small patches where the radiosity is not smooth, before any solve.

Measured on the Cornell box against a converged path-traced reference, the error of a
uniform mesh sits along the lines where two objects' surfaces meet (a box standing on the
floor, the room's corners) and along the shadow boundaries of the area light; elsewhere
the radiosity is smooth and large patches do. This meshing, after Heckbert 1992 and
Lischinski, Tampieri & Greenberg 1992 but kept on the quadtree of :mod:`patches`:

* **hidden leaves dropped** -- floor cells under a box see only the box's inside (a ray
  along their normal meets a back face first): they are invisible, receive nothing and, in
  the Gouraud display, would darken the vertices they share with the lit floor.
* **contact lines** -- the edges of one surface that lie in the plane of another (a box's
  bottom edges on the floor, a wall's edge on the floor): leaves of either surface that
  touch such a segment are split ``CONTACT_LEVELS`` times (an option, off by default: once
  the hidden cells are gone it did not pay on the Cornell box, see below).
* **near mesh objects** -- quad leaves closer to a mesh object (a scan, a sphere standing
  on a floor) than ``NEAR_REACH`` of their own size are split, ``NEAR_LEVELS`` times: the
  floor's cells grade down towards where the object stands, where its contact shadow is
  (Spot, 100k triangles, on an 8 m floor at 400 patches: the shadowed floor under it 0.095
  of the lit floor beside it, 0.22 without; ``tests/radiosity/test_radiosity_contact.py``).
  Distances are to the mesh as loaded (vertices and triangle centroids), not its clusters.
* **shadow boundaries** -- leaves whose corners (and centre) see different shares of the
  emitters (ray-cast visibility of a 4 x 4 grid on each light) or of the point, spot and
  directional lights (one shadow ray each, weighted by their irradiance) are split
  ``SHADOW_LEVELS`` times: penumbrae get small patches, fully lit and fully shadowed
  regions stay coarse.

The base grid is solved for so that the final patch count comes close to the target; a
scene whose meshes are clustered keeps the budget as a bound (the meshes are clustered
once, the quads' base grid is the finest whose refined cells fit the rest). Pure numpy,
scipy's k-d tree + embreex (no GL).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from shadelab.radiosity.direct import direct_lights, irradiance
from shadelab.radiosity.patches import (
    PatchSet,
    Surface,
    assemble,
    check_count,
    cluster_surfaces,
    leaf_corners,
    needs_clustering,
    polygon_area_normal,
    quad_leaves,
    scene_surfaces,
    uniform_patches,
)
from shadelab.radiosity.sampling import source_samples
from shadelab.scene.model import Scene
from shadelab.shading.lights import light_kind

CONTACT_LEVELS = 0  # quadtree splits along contact lines: off by default. Measured (Cornell,
#                    32x32 against 16k spp, ~1000 patches): hidden cells dropped 1.8 %, plus
#                    one contact level 2.3 % (the budget goes to thin strips along all room
#                    corners and the base grid coarsens), plus one shadow level 1.44 %
SHADOW_LEVELS = 1  # quadtree splits across the light's penumbrae (2 levels: 2.3 %, the base
#                   grid gets too coarse at this budget)
SHADOW_CONTRAST = 0.15  # split where the corners' visible share of the light differs by this
BASE_ROUNDS = 3  # base-grid adjustments towards the target count
FIT_ROUNDS = 10  # quad base budgets tried to fit a clustered scene's refined mesh in its count
FIT_SLACK = 0.03  # ... stopping within this share below the count
NEAR_LEVELS = 3  # quadtree splits of quad cells near a mesh object (a scan standing on a floor)
NEAR_REACH = 0.75  # ... while the cell's distance to the mesh is below this many cell sizes


def discontinuity_patches(scene: Scene, count: int, contact_levels: int = CONTACT_LEVELS,
                          shadow_levels: int = SHADOW_LEVELS, drop_hidden: bool = True,
                          near_levels: int | None = None) -> PatchSet:
    """About ``count`` patches: a regular base grid refined along contact lines, near mesh
    objects and across shadow boundaries, hidden cells dropped (see the module docstring).

    A scene whose meshes are clustered to the budget (:func:`patches.cluster_mesh`) keeps
    the budget as a bound: its meshes are clustered once, to their share of ``count``, and
    the quads' base grid is the finest whose refined cells fit the rest (at most ``count``
    patches in all)."""
    count = check_count(count)
    near_levels = NEAR_LEVELS if near_levels is None else near_levels
    prepared = _prepare_clustered(scene, count)
    if prepared is not None:
        return _fit_clustered(scene, count, prepared, contact_levels, shadow_levels,
                              drop_hidden, near_levels)
    base = count
    best = None
    for _ in range(BASE_ROUNDS):
        patches = _mesh(scene, max(1, base), contact_levels, shadow_levels, drop_hidden,
                        near_levels)
        if best is None or abs(len(patches) - count) < abs(len(best) - count):
            best = patches
        if len(patches) == 0 or abs(len(patches) - count) <= 0.03 * count:
            break
        base = max(1, int(round(base * count / len(patches))))
    best.info.update(meshing="discontinuity", contact_levels=contact_levels,
                     shadow_levels=shadow_levels, near_levels=near_levels)
    return best


@dataclass
class _Prepared:
    """What every base-grid round shares: surfaces with their meshes clustered, the quads'
    budget, the occluders' ray-casting scene and the original meshes' points."""

    surfaces: list[Surface]
    rest: int
    occluder: tuple
    near: tuple | None
    triangles_in: int

    def copy(self) -> list[Surface]:
        return [replace(s) for s in self.surfaces]


def _prepare_clustered(scene: Scene, count: int) -> _Prepared | None:
    surfaces = scene_surfaces(scene)
    if not surfaces or not needs_clustering(surfaces, count):
        return None
    # the meshes as they are, before clustering: what stands near a floor cell and what
    # shadows it (the direct light's shadow rays see the same, :mod:`.direct`)
    near = _near_points(surfaces)
    occluder = _surface_scene(surfaces)
    triangles_in = sum(len(s.faces) for s in surfaces if s.kind == "mesh")
    rest = cluster_surfaces(surfaces, count)
    return _Prepared(surfaces, rest, occluder, near, triangles_in)


def _fit_clustered(scene, count, prepared, contact_levels, shadow_levels, drop_hidden,
                   near_levels) -> PatchSet:
    """The finest quad base grid whose refined mesh stays within ``count`` patches."""
    import time

    start = time.perf_counter()
    rest = prepared.rest
    fits, over = 0, None  # quad budgets known to fit within count / to go over it
    budget, best = rest, None
    for _ in range(FIT_ROUNDS):
        patches = _mesh(scene, max(1, budget), contact_levels, shadow_levels, drop_hidden,
                        near_levels, prepared)
        if len(patches) <= count:
            fits = budget
            if best is None or len(patches) > len(best):
                best = patches
            if len(patches) >= (1.0 - FIT_SLACK) * count or over is None:
                break
        else:
            over = budget
            quads = int(np.count_nonzero(patches.rects[:, 0] >= 0))
            guess = int(budget * (rest - (len(patches) - count)) / max(quads, 1))
            if fits == 0 and 0 < guess < budget:  # first step: in proportion
                budget = guess
                continue
        budget = (fits + over) // 2
        if budget <= fits:
            break
    if best is None:  # even one cell per quad with its refinement is over: no refinement
        best = _mesh(scene, 1, 0, 0, drop_hidden, 0, prepared)
    best.info.update(meshing="discontinuity", contact_levels=contact_levels,
                     shadow_levels=shadow_levels, near_levels=near_levels, clustered=True,
                     mesh_triangles=prepared.triangles_in,
                     clustering_s=time.perf_counter() - start)
    return best


def _mesh(scene, base, contact_levels, shadow_levels, drop_hidden, near_levels=0,
          prepared: _Prepared | None = None) -> PatchSet:
    if prepared is None:
        grid = uniform_patches(scene, base)
        surfaces = grid.surfaces
        leaves = [(int(s), *map(int, r)) for s, r in
                  zip(grid.surface[grid.rects[:, 0] >= 0], grid.rects[grid.rects[:, 0] >= 0],
                      strict=True)]
        occluder = _surface_scene(surfaces)
        near = _near_points(surfaces) if near_levels else None
    else:
        surfaces = prepared.copy()
        leaves = quad_leaves(surfaces, base)
        occluder, near = prepared.occluder, prepared.near
    if drop_hidden:
        leaves = _visible(surfaces, leaves, occluder)
    segments = contact_segments(surfaces) if contact_levels else {}
    for _ in range(contact_levels):
        touch = leaves_on_segments(surfaces, leaves, segments)
        leaves = _split(leaves, touch)
    refined = bool(contact_levels)
    for _ in range(near_levels if near is not None else 0):
        chosen = near_occluders(surfaces, leaves, near)
        refined |= bool(chosen.any())
        leaves = _split(leaves, chosen)
    if drop_hidden and refined:
        leaves = _visible(surfaces, leaves, occluder)
    lights = _light_samples(scene, surfaces)
    points = direct_lights(scene)
    for _ in range(shadow_levels if len(lights[0]) or points else 0):
        leaves = _split(leaves, _penumbra(surfaces, leaves, lights, occluder, scene))
    # mesh surfaces (triangles) were split or clustered already: assemble adds them
    return assemble(scene, surfaces, leaves)


# ---------------------------------------------------------------------- geometry helpers
def leaf_polygons(surfaces: list[Surface], leaves: list[tuple]) -> np.ndarray:
    """(L, 4, 3) world corners of quadtree leaves (surface, x0, y0, x1, y1)."""
    if not leaves:
        return np.zeros((0, 4, 3))
    return leaf_corners(surfaces, np.asarray(leaves, np.int64).reshape(-1, 5))


def _split(leaves: list[tuple], chosen: np.ndarray) -> list[tuple]:
    out = []
    for leaf, split in zip(leaves, chosen, strict=True):
        s, x0, y0, x1, y1 = leaf
        if split and x1 - x0 > 1 and y1 - y0 > 1:
            xm, ym = (x0 + x1) // 2, (y0 + y1) // 2
            out += [(s, x0, y0, xm, ym), (s, xm, y0, x1, ym), (s, xm, ym, x1, y1),
                    (s, x0, ym, xm, y1)]
        else:
            out.append(leaf)
    return out


def _plane(corners: np.ndarray) -> tuple[np.ndarray, float]:
    _, n = polygon_area_normal(corners[None])
    return n[0], float(n[0] @ corners.mean(axis=0))


def _scale(surfaces: list[Surface]) -> float:
    pts = np.concatenate([s.corners for s in surfaces if s.kind == "quad"] or [np.zeros((1, 3))])
    return float(max(np.ptp(pts, axis=0).max(), 1e-12))


def _inside_convex(point: np.ndarray, corners: np.ndarray, normal: np.ndarray,
                   tol: float) -> bool:
    """Is a point (in the plane) inside a convex polygon, within ``tol``?"""
    for k in range(len(corners)):
        a, b = corners[k], corners[(k + 1) % len(corners)]
        edge = b - a
        inward = np.cross(normal, edge)
        inward /= max(np.linalg.norm(inward), 1e-300)
        if (point - a) @ inward < -tol:
            return False
    return True


def contact_segments(surfaces: list[Surface], tol: float | None = None
                     ) -> dict[int, list[tuple[np.ndarray, np.ndarray]]]:
    """Per quad surface: the segments (world end points) where another surface meets it.

    An edge of surface T whose ends both lie in the plane of S (within ``tol``) is a contact
    line of S -- where it crosses S's cells -- and, when it runs over S (its midpoint inside
    S), a contact line of T too (T's own boundary). Coplanar surfaces (a ceiling in pieces,
    the light set in it) do not meet in this sense.
    """
    quads = [i for i, s in enumerate(surfaces) if s.kind == "quad"]
    tol = 1e-6 * _scale(surfaces) if tol is None else tol
    planes = {i: _plane(surfaces[i].corners) for i in quads}
    out: dict[int, list] = {i: [] for i in quads}
    for s in quads:
        ns, ds = planes[s]
        for t in quads:
            nt, _ = planes[t]
            if t == s or abs(abs(float(ns @ nt)) - 1.0) < 1e-9:
                continue
            corners = surfaces[t].corners
            for k in range(4):
                a, b = corners[k], corners[(k + 1) % 4]
                if abs(a @ ns - ds) > tol or abs(b @ ns - ds) > tol:
                    continue
                out[s].append((a.copy(), b.copy()))
                if _inside_convex(0.5 * (a + b), surfaces[s].corners, ns, tol):
                    out[t].append((a.copy(), b.copy()))
    return out


def leaves_on_segments(surfaces: list[Surface], leaves: list[tuple],
                       segments: dict[int, list], tol: float | None = None) -> np.ndarray:
    """(L,) bool: leaves whose cell meets one of its surface's contact segments (touching
    counts; Cyrus-Beck clipping of each segment against the convex cell)."""
    tol = 1e-6 * _scale(surfaces) if tol is None else tol
    hit = np.zeros(len(leaves), bool)
    if not leaves:
        return hit
    polygons = leaf_polygons(surfaces, leaves)
    owner = np.array([leaf[0] for leaf in leaves])
    for s, segs in segments.items():
        members = np.flatnonzero(owner == s)
        if len(members) == 0 or not segs:
            continue
        poly = polygons[members]
        normal = _plane(surfaces[s].corners)[0]
        edge = np.roll(poly, -1, axis=1) - poly  # (M, 4, 3)
        inward = np.cross(normal, edge)
        inward /= np.maximum(np.linalg.norm(inward, axis=2, keepdims=True), 1e-300)
        for a, b in segs:
            lo = np.zeros(len(members))
            hi = np.ones(len(members))
            ok = np.ones(len(members), bool)
            for k in range(4):
                n = inward[:, k]
                num = ((a - poly[:, k]) * n).sum(axis=1) + tol  # >= 0 inside
                den = ((b - a)[None, :] * n).sum(axis=1)
                t = -num / np.where(den == 0.0, 1.0, den)
                ok &= ~((den == 0.0) & (num < 0.0))
                lo = np.where(den > 0.0, np.maximum(lo, t), lo)
                hi = np.where(den < 0.0, np.minimum(hi, t), hi)
            hit[members[ok & (lo <= hi)]] = True
    return hit


# ---------------------------------------------------------------------- ray casting
def _surface_scene(surfaces: list[Surface]):
    """(embree scene, front normals per triangle) of every surface (quads and meshes)."""
    import embreex.mesh_construction as mc
    import embreex.rtcore_scene as rs

    tris = []
    for s in surfaces:
        if s.kind == "quad":
            c = s.corners
            tris += [c[[0, 1, 2]], c[[0, 2, 3]]]
        else:
            tris += list(s.vertices[s.faces])
    tri = np.asarray(tris, float).reshape(-1, 3, 3)
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    length = np.linalg.norm(normal, axis=1)
    keep = length > 0
    tri, normal = tri[keep], normal[keep] / length[keep, None]
    scene = rs.EmbreeScene()
    mc.TriangleMesh(scene, np.ascontiguousarray(tri, np.float32))
    return scene, normal, _scale(surfaces)


def _probe_points(polygons: np.ndarray, inset: float) -> np.ndarray:
    """(L, 5, 3): the cell's centre and its corners pulled ``inset`` of the way in."""
    centre = polygons.mean(axis=1, keepdims=True)
    corners = polygons + inset * (centre - polygons)
    return np.concatenate([centre, corners], axis=1)


def _visible(surfaces, leaves, occluder) -> list[tuple]:
    """Leaves of which some probe point is not enclosed (its normal ray does not meet a back
    face first); the enclosed ones are inside a closed object and never seen."""
    if not leaves:
        return leaves
    scene, normals, scale = occluder
    polygons = leaf_polygons(surfaces, leaves)
    _, n = polygon_area_normal(polygons)
    points = _probe_points(polygons, 0.1)  # (L, 5, 3)
    eps = 1e-6 * scale
    origins = (points + eps * n[:, None, :]).reshape(-1, 3)
    dirs = np.repeat(n, 5, axis=0)
    hit = scene.run(origins.astype(np.float32), dirs.astype(np.float32), output=1)
    prim = hit["primID"]
    back = np.zeros(len(origins), bool)
    ok = prim >= 0
    back[ok] = (normals[prim[ok]] * dirs[ok]).sum(axis=1) > 0.0
    enclosed = back.reshape(len(leaves), 5).all(axis=1)
    return [leaf for leaf, e in zip(leaves, enclosed, strict=True) if not e]


def _light_samples(scene: Scene, surfaces: list[Surface]):
    """Sample points (M, 3), unit normals (M, 3) and areas (M,) on the emitting quads."""
    points, normals, areas = [], [], []
    for s in surfaces:
        if s.kind != "quad" or max(scene.materials[s.material].emission) <= 0.0:
            continue
        pts, w = source_samples(s.corners[None])
        area, n = polygon_area_normal(s.corners[None])
        points.append(pts[0])
        normals.append(np.repeat(n, len(pts[0]), axis=0))
        areas.append(area[0] * w[0])
    if not points:
        return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0)
    return np.concatenate(points), np.concatenate(normals), np.concatenate(areas)


def light_visibility(surfaces, points: np.ndarray, point_normals: np.ndarray, lights,
                     occluder) -> np.ndarray:
    """(P,) share of the unoccluded direct kernel cos cos dA / r^2 from the emitters that
    reaches each point (NaN where no emitter is in front of it)."""
    scene, _, scale = occluder
    lp, ln, la = lights
    eps = 1e-6 * scale
    x = points + eps * point_normals
    d = lp[None, :, :] - x[:, None, :]  # (P, M, 3)
    r2 = np.maximum((d * d).sum(axis=2), 1e-300)
    r = np.sqrt(r2)
    ci = np.maximum((d * point_normals[:, None, :]).sum(axis=2) / r, 0.0)
    cj = np.maximum(-(d * ln[None]).sum(axis=2) / r, 0.0)
    w = ci * cj * la[None] / r2
    origins = np.repeat(x, len(lp), axis=0)
    hit = scene.run(origins.astype(np.float32), d.reshape(-1, 3).astype(np.float32),
                    dists=np.full(len(origins), 1.0 - 1e-4, np.float32), query="OCCLUDED")
    seen = np.where((hit != -1).reshape(w.shape), 0.0, w).sum(axis=1)
    total = w.sum(axis=1)
    return np.where(total > 0.0, seen / np.maximum(total, 1e-300), np.nan)


def direct_visibility(scene: Scene, points: np.ndarray, point_normals: np.ndarray,
                      occluder) -> np.ndarray:
    """(P,) share of the point, spot and directional lights' unoccluded irradiance
    (:func:`shadelab.radiosity.direct.irradiance`, weighted by each light's mean Ip) that
    reaches each point past the surfaces (NaN where no light falls on it)."""
    scene_rt, _, scale = occluder
    eps = 1e-6 * scale
    seen = np.zeros(len(points))
    total = np.zeros(len(points))
    for light in direct_lights(scene):
        value = irradiance(light, points, point_normals) * float(np.mean(light.Ip))
        lit = np.flatnonzero(value > 0.0)
        if len(lit) == 0:
            continue
        to_light, distance = light_kind(light).to_light(points[lit])
        reach = np.where(np.isfinite(distance), distance - 2.0 * eps, 1e30)
        origins = points[lit] + eps * point_normals[lit]
        hit = scene_rt.run(origins.astype(np.float32), to_light.astype(np.float32),
                           dists=np.maximum(reach, eps).astype(np.float32), query="OCCLUDED")
        total[lit] += value[lit]
        seen[lit] += np.where(hit != -1, 0.0, value[lit])
    return np.where(total > 0.0, seen / np.maximum(total, 1e-300), np.nan)


def _spread(vis: np.ndarray) -> np.ndarray:
    """(L,) max - min over each row's finite values (NaN rows: -inf)."""
    return np.nanmax(np.where(np.isnan(vis), -np.inf, vis), axis=1) \
        - np.nanmin(np.where(np.isnan(vis), np.inf, vis), axis=1)


def _penumbra(surfaces, leaves, lights, occluder, scene: Scene | None = None) -> np.ndarray:
    """(L,) bool: leaves whose probe points see the emitters, or the scene's point, spot
    and directional lights, to different degrees."""
    if not leaves:
        return np.zeros(0, bool)
    polygons = leaf_polygons(surfaces, leaves)
    _, n = polygon_area_normal(polygons)
    points = _probe_points(polygons, 0.02).reshape(-1, 3)
    normals = np.repeat(n, 5, axis=0)
    out = np.zeros(len(leaves), bool)
    if len(lights[0]):
        spread = _spread(light_visibility(surfaces, points, normals, lights,
                                          occluder).reshape(len(leaves), 5))
        out |= np.isfinite(spread) & (spread > SHADOW_CONTRAST)
    if scene is not None and direct_lights(scene):
        spread = _spread(direct_visibility(scene, points, normals,
                                           occluder).reshape(len(leaves), 5))
        out |= np.isfinite(spread) & (spread > SHADOW_CONTRAST)
    return out


# ---------------------------------------------------------------------- near mesh objects
def _near_points(surfaces: list[Surface]):
    """(k-d tree, None) of the mesh surfaces' vertices and triangle centroids, as they are
    before any clustering (a scan's feet, not the cluster they merge into); None without
    meshes."""
    parts = []
    for s in surfaces:
        if s.kind == "mesh" and len(s.faces):
            parts += [s.vertices, s.vertices[s.faces].mean(axis=1)]
    if not parts:
        return None  # (and scipy, seconds to import, stays out of a room of quads)
    from scipy.spatial import cKDTree

    return cKDTree(np.concatenate(parts)), None


def near_occluders(surfaces: list[Surface], leaves: list[tuple], near,
                   reach: float = NEAR_REACH) -> np.ndarray:
    """(L,) bool: quad leaves closer to a mesh object than ``reach`` times their own size
    (their longer side) and facing it. Split level after level, they grade the
    mesh towards where the object stands on the surface, where its contact shadow is."""
    out = np.zeros(len(leaves), bool)
    if near is None or not leaves:
        return out
    tree = near[0]
    polygons = leaf_polygons(surfaces, leaves)
    _, n = polygon_area_normal(polygons)
    centre = polygons.mean(axis=1)
    size = np.maximum(np.linalg.norm(polygons[:, 1] - polygons[:, 0], axis=1),
                      np.linalg.norm(polygons[:, 3] - polygons[:, 0], axis=1))
    distance, index = tree.query(centre, distance_upper_bound=float(reach * size.max()))
    found = np.isfinite(distance)
    ahead = np.zeros(len(leaves), bool)
    if found.any():
        where = tree.data[index[found]]
        ahead[found] = ((where - centre[found]) * n[found]).sum(axis=1) \
            >= -0.5 * size[found]
    return found & ahead & (distance < reach * size)


def min_cell_size(surface: Surface, levels: int) -> float:
    """World size of a base cell of ``surface`` after ``levels`` splits (the longer side)."""
    p0, p1, _, p3 = surface.corners
    return max(np.linalg.norm(p1 - p0) / surface.grid[0],
               np.linalg.norm(p3 - p0) / surface.grid[1]) / (1 << levels)
