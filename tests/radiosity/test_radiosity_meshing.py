"""Discontinuity meshing (shadelab.radiosity.meshing): closed-form checks.

* area: without dropping, the refined mesh tiles every surface exactly (sum of areas);
* hidden cells: on the Cornell box the dropped cells are the floor under the two boxes;
* contact lines: cells along a box's bottom edges are split to the stated size;
* shadow boundaries: a square light over a parallel square occluder casts, on the floor,
  an umbra ||d||_inf <= 2b - a and a penumbra out to 2b + a (a, b: half-sizes, occluder
  half-way up): the split cells are those that meet that ring, and nothing else.
"""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.errors import ShadeLabError
from shadelab.radiosity import meshing
from shadelab.radiosity.patches import scene_surfaces, uniform_patches
from shadelab.radiosity.solution import base_patches
from shadelab.scene.preset import load_preset, scene_from_dict

A, B = 0.1, 0.12  # light and occluder half-sizes (umbra 0.14, penumbra out to 0.34)
FOOTPRINTS = [np.array([(130, 65), (82, 225), (240, 272), (290, 114)], float),
              np.array([(423, 247), (265, 296), (314, 456), (472, 406)], float)]


def _shadow_scene():
    def quad(name, material, vertices):
        return {"name": name, "shape": "quad", "material": material, "normals": "flat",
                "vertices": vertices}

    lo, hi = 0.5 - A, 0.5 + A
    olo, ohi = 0.5 - B, 0.5 + B
    raw = {
        "schema_version": 1, "Ia": [0, 0, 0],
        "camera": {"eye": [0.5, 0.5, -1.0], "target": [0.5, 0.5, 0.5], "up": [0, 1, 0],
                   "fov_y": 60.0, "near": 0.01},
        "lights": [{"name": "l", "kind": "point", "position": [0.5, 0.9, 0.5],
                    "Ip": [1, 1, 1], "stand_in": True}],
        "materials": {
            "white": {"ka": 0.0, "kd": 1.0, "Od": [0.5, 0.5, 0.5], "ks": 0.0},
            "light": {"ka": 0.0, "kd": 0.0, "ks": 0.0, "Od": [0.8, 0.8, 0.8],
                      "emission": [10.0, 10.0, 10.0]}},
        "objects": [
            quad("floor", "white", [[1, 0, 0], [0, 0, 0], [0, 0, 1], [1, 0, 1]]),
            quad("light", "light", [[hi, 1, lo], [hi, 1, hi], [lo, 1, hi], [lo, 1, lo]]),
            quad("occluder", "white", [[ohi, 0.5, olo], [ohi, 0.5, ohi], [olo, 0.5, ohi],
                                       [olo, 0.5, olo]])],
    }
    return scene_from_dict(raw, "<test>")


def _floor_cells(patches, surface=0):
    rows = np.flatnonzero(patches.surface == surface)
    return rows, patches.polygons[rows]


def _inside(points, polygon):
    """Points (P, 2) inside a convex polygon (K, 2), either orientation."""
    sign = []
    for k in range(len(polygon)):
        a, b = polygon[k], polygon[(k + 1) % len(polygon)]
        sign.append((b[0] - a[0]) * (points[:, 1] - a[1]) - (b[1] - a[1]) * (points[:, 0] - a[0]))
    sign = np.array(sign)
    return (sign >= 0).all(axis=0) | (sign <= 0).all(axis=0)


@pytest.mark.parametrize("preset, rtol", [(None, 1e-12), ("cornell", 1e-6)])
def test01_area_is_preserved(preset, rtol):
    """Exact on planar quads; the Cornell walls are slightly non-planar (a 3.2 mm twist),
    where a bilinear cell's flat area differs from its children's by ~4e-7."""
    scene = load_preset(preset) if preset else _shadow_scene()
    patches = meshing.discontinuity_patches(scene, 500, contact_levels=2, shadow_levels=2,
                                            drop_hidden=False)
    total = sum(meshing.polygon_area_normal(s.corners[None])[0][0]
                for s in scene_surfaces(scene))
    np.testing.assert_allclose(patches.areas.sum(), total, rtol=rtol)
    assert patches.areas.min() < 0.5 * uniform_patches(scene, 500).areas.max()  # refined


def test02_hidden_cells_are_the_floor_under_the_boxes():
    scene = load_preset("cornell")
    full = meshing._mesh(scene, 600, 0, 0, drop_hidden=False)  # noqa: SLF001  (same grid)
    kept = meshing._mesh(scene, 600, 0, 0, drop_hidden=True)  # noqa: SLF001
    # the same grid (same base count) less the dropped cells, all of them on the floor
    lost = full.areas.sum() - kept.areas.sum()
    footprint = sum(0.5 * abs(float(np.sum(f[:, 0] * np.roll(f[:, 1], -1)
                                           - np.roll(f[:, 0], -1) * f[:, 1])))
                    for f in FOOTPRINTS)
    assert 0.25 * footprint < lost <= footprint  # whole cells only (57 mm at 600 patches)
    kept_keys = {tuple(np.round(c, 6)) for c in kept.centers}
    dropped = np.array([c for c in full.centers if tuple(np.round(c, 6)) not in kept_keys])
    assert len(dropped) == len(full) - len(kept) > 0
    assert np.allclose(dropped[:, 1], 0.0)  # all on the floor
    assert sum(_inside(dropped[:, [0, 2]], f) for f in FOOTPRINTS).all()  # under a box
    np.testing.assert_allclose(lost, full.areas[~np.isin(np.arange(len(full)),
                               [i for i, c in enumerate(full.centers)
                                if tuple(np.round(c, 6)) in kept_keys])].sum(), rtol=1e-9)


def test03_cells_along_contact_lines_are_small():
    scene = load_preset("cornell")
    levels = 2
    patches = meshing.discontinuity_patches(scene, 400, contact_levels=levels,
                                            shadow_levels=0)
    surfaces = patches.surfaces
    segments = meshing.contact_segments(surfaces)
    # The floor meets three walls (its own edges and theirs) and the two boxes' bottom edges
    box_edges = [(a, b) for a, b in segments[0] if 0.0 < a[0] < 500.0 and 0.0 < a[2] < 500.0]
    assert len(box_edges) == 8 and len(segments[0]) >= 8 + 3
    leaves = [(int(s), *map(int, r)) for s, r in zip(patches.surface, patches.rects,
                                                      strict=True) if r[0] >= 0]
    touch = meshing.leaves_on_segments(surfaces, leaves, segments)
    limit = max(meshing.min_cell_size(surfaces[s], levels) for s in range(len(surfaces))
                if surfaces[s].kind == "quad")
    sizes = np.array([np.ptp(p, axis=0).max() for p in meshing.leaf_polygons(surfaces, leaves)])
    assert touch.sum() > 50
    floor = np.array([leaf[0] == 0 for leaf in leaves])
    floor_limit = meshing.min_cell_size(surfaces[0], levels)
    assert sizes[touch & floor].max() <= floor_limit * 1.5 + 1e-9  # cells are parallelograms
    assert sizes[touch].max() <= limit * 1.5 + 1e-9
    assert sizes[~touch].max() > 2 * floor_limit  # away from them the base grid stays


def test04_light_visibility_closed_form():
    scene = _shadow_scene()
    surfaces = scene_surfaces(scene)
    occluder = meshing._surface_scene(surfaces)  # noqa: SLF001
    lights = meshing._light_samples(scene, surfaces)  # noqa: SLF001
    x = np.array([0.5, 0.5 + 0.1, 0.5 + 0.24, 0.5 + 0.45])
    points = np.stack([x, np.zeros(4), np.full(4, 0.5)], axis=1)
    vis = meshing.light_visibility(surfaces, points, np.tile([0.0, 1.0, 0.0], (4, 1)), lights,
                                   occluder)
    assert vis[0] == 0.0 and vis[1] == 0.0  # umbra: ||d|| <= 2b - a = 0.14
    assert 0.1 < vis[2] < 0.9  # penumbra
    assert vis[3] == 1.0  # lit: ||d|| >= 2b + a = 0.34


def test05_shadow_boundary_split_follows_the_penumbra():
    scene = _shadow_scene()
    split = meshing.discontinuity_patches(scene, 400, 0, 1)
    rows, polygons = _floor_cells(split)
    size = np.ptp(polygons, axis=1).max(axis=1)
    coarse = size.max()
    d = np.abs(polygons[:, :, [0, 2]] - 0.5).max(axis=2)  # ||corner - centre||_inf
    near, far = d.min(axis=1), d.max(axis=1)
    small = size < 0.75 * coarse
    assert small.sum() >= 16
    # every split cell lies within one coarse cell of the analytic penumbra ring
    umbra, lit = 2 * B - A, 2 * B + A
    assert (far[small] >= umbra - coarse).all() and (near[small] <= lit + coarse).all()
    # cells entirely in the umbra or entirely lit (with a coarse cell of margin) stay coarse
    deep = (far < umbra - coarse) | (near > lit + coarse)
    assert deep.any() and not (small & deep).any()


def test06_meshing_option():
    scene = load_preset("cornell")
    with pytest.raises(ShadeLabError, match="meshing"):
        base_patches(scene, 100, "nope")
    patches = base_patches(scene, 300, "discontinuity")
    assert patches.info["meshing"] == "discontinuity"
    assert abs(len(patches) - 300) < 0.15 * 300
    assert len(base_patches(scene, 300)) == len(uniform_patches(scene, 300))
