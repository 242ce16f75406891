"""Patch radiosities to per-vertex radiance on world-space triangle meshes (Gouraud display).

Vertex values are the area-weighted average of the patches that touch the vertex on the same
surface (the lecture's "radiosity & Gouraud shading" step), extrapolated at the surface's
boundary and then corrected a few times so that each patch's interpolated mean keeps its
radiosity (plain averaging flattens peaks and fills dips: -4 % in the Cornell image's mean).

Adaptive subdivision leaves T-vertices (a fine patch's corner in the middle of a coarse
neighbour's edge); drawn naively the coarse side interpolates its own two corners along that
edge and the fine side uses the T-vertex's value: a visible crack in the shading. The
conforming display triangulates every leaf as a fan through all the vertices on its
boundary, so both sides share those values.
"""

from __future__ import annotations

import numpy as np

from shadelab.radiosity.patches import FINE, PatchSet

Mesh = tuple[np.ndarray, np.ndarray, np.ndarray]  # vertices (V,3), faces (F,3), radiance (V,3)


def display_meshes(patches: PatchSet, radiance: np.ndarray, conforming: bool = True) -> list[Mesh]:
    """One (vertices, faces, vertex_radiance) per surface; ``radiance`` is (N, 3) per patch."""
    meshes, owners = [], []
    for index, surface in enumerate(patches.surfaces):
        members = np.flatnonzero(patches.surface == index)
        if len(members) == 0:
            continue
        if surface.kind == "quad":
            meshes.append(_quad_display(patches, index, members, radiance, conforming))
        else:
            meshes.append(_mesh_display(patches, index, members, radiance))
        owners.append(index)
    if not patches.surfaces:  # a bare patch set: one flat-shaded quad per patch
        meshes.append(_bare_display(patches, radiance))
    elif conforming:
        _share_coplanar_vertices(patches, owners, meshes)
    return meshes


def _share_coplanar_vertices(patches: PatchSet, owners: list[int], meshes: list[Mesh]) -> None:
    """Average the values of vertices that coplanar quads of one material share (a floor or
    ceiling modelled in pieces), so no seam shows where the pieces meet. In place."""
    keys, where = [], []
    span = float(np.ptp(patches.polygons.reshape(-1, 3), axis=0).max()) or 1.0
    for m, index in enumerate(owners):
        surface = patches.surfaces[index]
        if surface.kind != "quad":
            continue
        normal = patches.normals[np.flatnonzero(patches.surface == index)[0]]
        vertices = meshes[m][0]
        q = np.round(vertices / (span * 1e-7)).astype(np.int64)
        n = np.round(normal * 1e4).astype(np.int64)
        for v in range(len(vertices)):
            keys.append((surface.material, *n, *q[v]))
            where.append((m, v))
    groups: dict[tuple, list] = {}
    for key, item in zip(keys, where, strict=True):
        groups.setdefault(key, []).append(item)
    for items in groups.values():
        if len({m for m, _ in items}) < 2:
            continue
        mean = np.mean([meshes[m][2][v] for m, v in items], axis=0)
        for m, v in items:
            meshes[m][2][v] = mean


def _quad_display(patches: PatchSet, index: int, members: np.ndarray, radiance: np.ndarray,
                  conforming: bool) -> Mesh:
    surface = patches.surfaces[index]
    rects = patches.rects[members]
    corners = np.concatenate([rects[:, [0, 1]], rects[:, [2, 1]], rects[:, [2, 3]],
                              rects[:, [0, 3]]])
    points, inverse = np.unique(corners, axis=0, return_inverse=True)
    inverse = inverse.reshape(4, len(members)).T  # (leaves, 4) vertex ids, ccw
    # Which leaves touch which vertices (closed rectangles: T-vertices count for both sides)
    px, py = points[:, 0][None, :], points[:, 1][None, :]
    inside = ((px >= rects[:, 0:1]) & (px <= rects[:, 2:3]) & (py >= rects[:, 1:2])
              & (py <= rects[:, 3:4]))  # (leaves, V)
    values = _area_average(inside, patches.areas[members], radiance[members])
    values = _extrapolate_boundary(points, inverse, surface, patches.areas[members],
                                   radiance[members], values)
    values = _match_patch_means(inside, inverse, patches.areas[members], radiance[members],
                                values)
    vertices = surface.point(points[:, 0], points[:, 1])
    faces, extra_v, extra_c = [], [], []
    for k in range(len(members)):
        x0, y0, x1, y1 = rects[k]
        on_edge = np.flatnonzero(inside[k] & ((px[0] == x0) | (px[0] == x1) | (py[0] == y0)
                                              | (py[0] == y1)))
        a, b, c, d = inverse[k]
        if not conforming or len(on_edge) == 4:
            faces += [(a, b, c), (a, c, d)]
            continue
        # Fan from the leaf's centre through every boundary vertex, counter-clockwise
        order = on_edge[np.argsort(_perimeter(points[on_edge], x0, y0, x1, y1))]
        centre = len(points) + len(extra_v)
        extra_v.append(surface.point(np.array((x0 + x1) / 2.0), np.array((y0 + y1) / 2.0)))
        extra_c.append(values[[a, b, c, d]].mean(axis=0))
        faces += [(centre, int(order[m]), int(order[(m + 1) % len(order)]))
                  for m in range(len(order))]
    if extra_v:
        vertices = np.concatenate([vertices, np.asarray(extra_v)])
        values = np.concatenate([values, np.asarray(extra_c)])
    return vertices, np.asarray(faces, np.int64), values


RECONSTRUCTION_SWEEPS = 3  # corrections that bring each patch's corner mean to its value


def _match_patch_means(touch, corners, areas, radiance, values) -> np.ndarray:
    """Nudge vertex values so that each patch's Gouraud mean (its corners' mean) matches its
    radiosity: averaging alone flattens peaks and fills dips (a bias in the image's mean)."""
    weights = touch * areas[:, None]
    total = np.maximum(weights.sum(axis=0), 1e-300)[:, None]
    for _ in range(RECONSTRUCTION_SWEEPS):
        residual = radiance - values[corners].mean(axis=1)
        values = np.maximum(values + (weights.T @ residual) / total, 0.0)
    return values


def _extrapolate_boundary(points, corners, surface, areas, radiance, values) -> np.ndarray:
    """Boundary vertices extrapolated through their patch: 2 B_k - (opposite corner), averaged
    over the patches at the vertex and kept >= 0.

    A plain average puts a boundary vertex at its patches' mean, which flattens the fall-off
    into corners and along shadowed edges; extrapolating from the interior keeps the slope
    (Cohen & Wallace 1993, "Radiosity and Realistic Image Synthesis", ch. 9).
    """
    extent = (surface.grid[0] * FINE, surface.grid[1] * FINE)
    x, y = points[:, 0], points[:, 1]
    boundary = (x == 0) | (y == 0) | (x == extent[0]) | (y == extent[1])
    total = np.zeros_like(values)
    weight = np.zeros(len(values))
    for k in range(len(corners)):
        for c in range(4):
            b, o = corners[k, c], corners[k, (c + 2) % 4]
            if boundary[b] and not boundary[o]:
                total[b] += areas[k] * (2.0 * radiance[k] - values[o])
                weight[b] += areas[k]
    done = weight > 0
    out = values.copy()
    out[done] = np.maximum(total[done] / weight[done, None], 0.0)
    return out


def _perimeter(points: np.ndarray, x0, y0, x1, y1) -> np.ndarray:
    """Position of boundary points along the rectangle's perimeter, counter-clockwise from
    (x0, y0): bottom edge, right edge, top edge (leftwards), left edge (downwards)."""
    x, y = points[:, 0].astype(float), points[:, 1].astype(float)
    w, h = float(x1 - x0), float(y1 - y0)
    return np.where(y == y0, x - x0,
                    np.where(x == x1, w + (y - y0),
                             np.where(y == y1, w + h + (x1 - x), 2 * w + h + (y1 - y))))


def _area_average(touch: np.ndarray, areas: np.ndarray, radiance: np.ndarray) -> np.ndarray:
    """(V, 3) area-weighted average over the patches (rows of ``touch``) at each vertex."""
    weights = touch * areas[:, None]
    total = np.maximum(weights.sum(axis=0), 1e-300)
    return (weights.T @ radiance) / total[:, None]


def _mesh_display(patches: PatchSet, index: int, members: np.ndarray,
                  radiance: np.ndarray) -> Mesh:
    surface = patches.surfaces[index]
    faces = patches.tri[members]
    values = np.zeros((len(surface.vertices), 3))
    weight = np.zeros(len(surface.vertices))
    for corner in range(3):
        np.add.at(values, faces[:, corner], radiance[members] * patches.areas[members, None])
        np.add.at(weight, faces[:, corner], patches.areas[members])
    return surface.vertices, faces, values / np.maximum(weight, 1e-300)[:, None]


def _bare_display(patches: PatchSet, radiance: np.ndarray) -> Mesh:
    n = len(patches)
    vertices = patches.polygons.reshape(-1, 3)
    base = 4 * np.arange(n)[:, None]
    faces = np.concatenate([base + [0, 1, 2], base + [0, 2, 3]])
    return vertices, faces, np.repeat(radiance, 4, axis=0)


def crack_report(patches: PatchSet, radiance: np.ndarray) -> dict:
    """T-vertex cracks for the failure gallery, naive display against the conforming one.

    ``t_vertices``: leaf corners inside a neighbour's edge. ``max_jump`` / ``mean_jump``: at
    those, |value - what the coarse neighbour's naive triangles interpolate there| (radiance).
    ``naive_open_edges`` / ``conforming_open_edges``: triangle edges inside a surface used by
    one triangle only (a crack in the mesh; 0 when conforming).
    """
    jumps, open_naive, open_conf = [], 0, 0
    for index, surface in enumerate(patches.surfaces):
        members = np.flatnonzero(patches.surface == index)
        if surface.kind != "quad" or len(members) == 0:
            continue
        rects = patches.rects[members]
        corners = np.concatenate([rects[:, [0, 1]], rects[:, [2, 1]], rects[:, [2, 3]],
                                  rects[:, [0, 3]]])
        points = np.unique(corners, axis=0)
        lookup = {tuple(p): i for i, p in enumerate(points)}
        _, naive_faces, values = _quad_display(patches, index, members, radiance, False)
        _, conf_faces, _ = _quad_display(patches, index, members, radiance, True)
        open_naive += _open_interior_edges(naive_faces, points)
        open_conf += _open_interior_edges(conf_faces, points)
        for x0, y0, x1, y1 in rects:
            for vid, (x, y) in enumerate(points):
                if (y == y0 or y == y1) and x0 < x < x1:
                    t, ends = (x - x0) / (x1 - x0), ((x0, y), (x1, y))
                elif (x == x0 or x == x1) and y0 < y < y1:
                    t, ends = (y - y0) / (y1 - y0), ((x, y0), (x, y1))
                else:
                    continue
                naive = (1 - t) * values[lookup[ends[0]]] + t * values[lookup[ends[1]]]
                jumps.append(float(np.abs(naive - values[vid]).max()))
    jumps = np.asarray(jumps)
    return {"t_vertices": len(jumps), "max_jump": float(jumps.max(initial=0.0)),
            "mean_jump": float(jumps.mean()) if len(jumps) else 0.0,
            "naive_open_edges": open_naive, "conforming_open_edges": open_conf}


def _open_interior_edges(faces: np.ndarray, points: np.ndarray) -> int:
    """Edges used by exactly one triangle that do not lie on the surface's outer boundary."""
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), 1)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    lo, hi = points.min(axis=0), points.max(axis=0)
    count = 0
    for a, b in unique[counts == 1]:
        if a >= len(points) or b >= len(points):
            count += 1  # a fan centre is never on the boundary
            continue
        pa, pb = points[a], points[b]
        on_outer = any((pa[k] == bound[k] and pb[k] == bound[k])
                       for bound in (lo, hi) for k in (0, 1))
        count += 0 if on_outer else 1
    return count


# ---------------------------------------------------------------- the viewer's cached plan
class DisplayPlan:
    """:func:`display_meshes` (conforming) of one patch set with everything that depends on
    the geometry only worked out once: the viewer's shot-by-shot job redraws the same patches
    after every chunk of shots, so each update is a few scatter-adds over (patch, vertex)
    pairs instead of Python loops over patches. ``meshes(radiance)`` equals
    ``display_meshes(patches, radiance)`` to rounding (tests/radiosity/test_radiosity_display.py).
    """

    def __init__(self, patches: PatchSet):
        self.patches = patches
        self.parts: list[tuple] = []      # ("quad", plan dict) | ("mesh", index, members)
        owners = []
        for index, surface in enumerate(patches.surfaces):
            members = np.flatnonzero(patches.surface == index)
            if len(members) == 0:
                continue
            if surface.kind == "quad":
                self.parts.append(("quad", _quad_plan(patches, index, members)))
            else:
                self.parts.append(("mesh", index, members))
            owners.append(index)
        self.bare = not patches.surfaces
        self.groups = None
        if not self.bare:
            probe = [(_plan_vertices(part), None, None) if part[0] == "quad"
                     else (patches.surfaces[part[1]].vertices, None, None)
                     for part in self.parts]
            self.groups = _coplanar_groups(patches, owners, probe)

    def meshes(self, radiance: np.ndarray) -> list[Mesh]:
        radiance = np.asarray(radiance, np.float64)
        if self.bare:
            return [_bare_display(self.patches, radiance)]
        out = []
        for part in self.parts:
            if part[0] == "quad":
                out.append(_quad_values(part[1], radiance))
            else:
                out.append(_mesh_display(self.patches, part[1], part[2], radiance))
        if self.groups is not None:
            _apply_groups(self.groups, out)
        return out


def _plan_vertices(part) -> np.ndarray:
    return part[1]["vertices"]


def _quad_plan(patches: PatchSet, index: int, members: np.ndarray) -> dict:
    """What :func:`_quad_display` (conforming) computes from the geometry alone."""
    surface = patches.surfaces[index]
    rects = patches.rects[members]
    areas = patches.areas[members]
    corners = np.concatenate([rects[:, [0, 1]], rects[:, [2, 1]], rects[:, [2, 3]],
                              rects[:, [0, 3]]])
    points, inverse = np.unique(corners, axis=0, return_inverse=True)
    inverse = inverse.reshape(4, len(members)).T
    px, py = points[:, 0][None, :], points[:, 1][None, :]
    inside = ((px >= rects[:, 0:1]) & (px <= rects[:, 2:3]) & (py >= rects[:, 1:2])
              & (py <= rects[:, 3:4]))
    leaf, vert = np.nonzero(inside)
    total = np.maximum(np.bincount(vert, areas[leaf], len(points)), 1e-300)
    # boundary extrapolation: (vertex b, opposite corner o, leaf k) triples
    extent = (surface.grid[0] * FINE, surface.grid[1] * FINE)
    x, y = points[:, 0], points[:, 1]
    boundary = (x == 0) | (y == 0) | (x == extent[0]) | (y == extent[1])
    kk = np.repeat(np.arange(len(members)), 4)
    bb = inverse.ravel()
    oo = inverse[:, [2, 3, 0, 1]].ravel()
    keep = boundary[bb] & ~boundary[oo]
    kk, bb, oo = kk[keep], bb[keep], oo[keep]
    ext_weight = np.bincount(bb, areas[kk], len(points))
    vertices = surface.point(points[:, 0], points[:, 1])
    faces, extra_v, extra_corners = [], [], []
    for k in range(len(members)):
        x0, y0, x1, y1 = rects[k]
        on_edge = np.flatnonzero(inside[k] & ((px[0] == x0) | (px[0] == x1) | (py[0] == y0)
                                              | (py[0] == y1)))
        a, b, c, d = inverse[k]
        if len(on_edge) == 4:
            faces += [(a, b, c), (a, c, d)]
            continue
        order = on_edge[np.argsort(_perimeter(points[on_edge], x0, y0, x1, y1))]
        centre = len(points) + len(extra_v)
        extra_v.append(surface.point(np.array((x0 + x1) / 2.0), np.array((y0 + y1) / 2.0)))
        extra_corners.append((a, b, c, d))
        faces += [(centre, int(order[m]), int(order[(m + 1) % len(order)]))
                  for m in range(len(order))]
    if extra_v:
        vertices = np.concatenate([vertices, np.asarray(extra_v)])
    return {"members": members, "areas": areas, "leaf": leaf, "vert": vert, "total": total,
            "n_points": len(points), "corners": inverse, "kk": kk, "bb": bb, "oo": oo,
            "ext_weight": ext_weight, "vertices": vertices,
            "faces": np.asarray(faces, np.int64).reshape(-1, 3),
            "extra_corners": np.asarray(extra_corners, np.int64).reshape(-1, 4)}


def _scatter(index: np.ndarray, values: np.ndarray, size: int) -> np.ndarray:
    """(size, 3): the rows of ``values`` summed into ``index``."""
    return np.stack([np.bincount(index, values[:, c], size) for c in range(3)], axis=1)


def _quad_values(plan: dict, radiance: np.ndarray) -> Mesh:
    """:func:`_quad_display`'s vertex values from a :func:`_quad_plan`."""
    rad = radiance[plan["members"]]
    areas, leaf, vert, total = plan["areas"], plan["leaf"], plan["vert"], plan["total"]
    n = plan["n_points"]
    weighted = areas[leaf, None] * rad[leaf]
    values = _scatter(vert, weighted, n) / total[:, None]
    kk, bb, oo, w = plan["kk"], plan["bb"], plan["oo"], plan["ext_weight"]
    if len(kk):
        ext = _scatter(bb, areas[kk, None] * (2.0 * rad[kk] - values[oo]), n)
        done = w > 0
        values = values.copy()
        values[done] = np.maximum(ext[done] / w[done, None], 0.0)
    corners = plan["corners"]
    for _ in range(RECONSTRUCTION_SWEEPS):
        residual = rad - values[corners].mean(axis=1)
        values = np.maximum(values + _scatter(vert, areas[leaf, None] * residual[leaf], n)
                            / total[:, None], 0.0)
    if len(plan["extra_corners"]):
        values = np.concatenate([values, values[plan["extra_corners"]].mean(axis=1)])
    return plan["vertices"], plan["faces"], values


def _coplanar_groups(patches: PatchSet, owners: list[int], meshes: list) -> tuple | None:
    """The vertex groups :func:`_share_coplanar_vertices` averages: (mesh offsets, member
    positions in the concatenated values, group id per member, group count)."""
    keys, where = [], []
    span = float(np.ptp(patches.polygons.reshape(-1, 3), axis=0).max()) or 1.0
    offsets = np.cumsum([0] + [len(m[0]) for m in meshes])
    for m, index in enumerate(owners):
        surface = patches.surfaces[index]
        if surface.kind != "quad":
            continue
        normal = patches.normals[np.flatnonzero(patches.surface == index)[0]]
        q = np.round(meshes[m][0] / (span * 1e-7)).astype(np.int64)
        nk = tuple(np.round(normal * 1e4).astype(np.int64))
        for v in range(len(q)):
            keys.append((surface.material, *nk, *q[v]))
            where.append((m, v))
    groups: dict[tuple, list] = {}
    for key, item in zip(keys, where, strict=True):
        groups.setdefault(key, []).append(item)
    members, gid, g = [], [], 0
    for items in groups.values():
        if len({m for m, _ in items}) < 2:
            continue
        g += 1
        for m, v in items:
            members.append(offsets[m] + v)
            gid.append(g - 1)
    if not members:
        return None
    gid = np.asarray(gid, np.int64)
    return offsets, np.asarray(members, np.int64), gid, int(gid.max()) + 1


def _apply_groups(groups: tuple, meshes: list) -> None:
    offsets, members, gid, count = groups
    values = np.concatenate([m[2] for m in meshes])
    sums = _scatter(gid, values[members], count)
    sizes = np.bincount(gid, minlength=count)
    values[members] = sums[gid] / sizes[gid, None]
    for m in range(len(meshes)):
        meshes[m] = (meshes[m][0], meshes[m][1], values[offsets[m]:offsets[m + 1]])
