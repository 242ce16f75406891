"""Open casters' merged shadow volumes (issue 13.5: cornell's blocks are open quads).

``open_volume`` is the union of the per-triangle volumes with the sides that cancel left out:
the stencil must be the very same as with one per-triangle volume per caster, with fewer
volume triangles."""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.geometry.silhouette import (
    light_homogeneous,
    open_caster_groups,
    open_volume,
    per_triangle_volume,
)
from shadelab.scene import load_preset

QUAD = np.array([[0.0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1]])
LIGHT = light_homogeneous("point", (0.3, 3.0, 0.6), None)


def _count(volume, point: np.ndarray, distance: float = 1e4) -> int:
    """Signed crossings of a ray from ``point`` far away with the volume made finite (its
    winding number about the point, as the z-fail count of a visible surface there)."""
    vertices, faces = volume.finite(distance)
    tri = vertices[faces]
    d = np.array([0.123, -0.9, 0.417])
    d /= np.linalg.norm(d)
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    p = np.cross(d, e2)
    det = np.einsum("ij,ij->i", e1, p)
    ok = np.abs(det) > 1e-15
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = point - tri[:, 0]
    u = np.einsum("ij,ij->i", s, p) * inv
    q = np.cross(s, e1)
    v = (q @ d) * inv
    t = np.einsum("ij,ij->i", e2, q) * inv
    hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)
    normal = np.cross(e1, e2)
    return int(np.sum(np.sign(normal[hit] @ d)))


def _unmatched_edges(volume) -> int:
    """Directed edges of the volume's faces with no opposite edge (0 for a closed surface):
    points by position, points at infinity by direction (w = 0), to 1e-9."""
    v = volume.vertices.copy()
    far = v[:, 3] == 0.0
    v[far, :3] /= np.linalg.norm(v[far, :3], axis=1, keepdims=True)
    _, point = np.unique(np.round(v, 9), axis=0, return_inverse=True)
    f = point.reshape(-1)[volume.faces]
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    edges = edges[edges[:, 0] != edges[:, 1]]
    key = np.sort(edges, axis=1)
    sign = np.where(edges[:, 0] < edges[:, 1], 1, -1)
    _, group = np.unique(key, axis=0, return_inverse=True)
    return int(np.abs(np.bincount(group.reshape(-1), weights=sign)).sum())


def test_a_flat_quad_loses_its_diagonal_and_counts_the_same():
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    merged = open_volume([(QUAD, faces)], LIGHT, 0.01)
    every = per_triangle_volume(QUAD, faces, LIGHT, 0.01)
    assert merged.method == "open"
    assert _unmatched_edges(merged) == 0
    assert len(merged.faces) == 12 and len(every.faces) == 16   # 4 sides, not 6
    assert len(merged.silhouette) == 4                            # the outline
    rng = np.random.default_rng(1)
    points = rng.uniform([-1.0, -3.0, -1.0], [2.0, 0.5, 2.0], (300, 3))
    counts = [(_count(merged, p), _count(every, p)) for p in points]
    assert all(a == b for a, b in counts)
    assert {a for a, _ in counts} == {0, 1}        # points in the shadow and out of it


def test_touching_casters_facing_both_ways_count_the_same():
    """A bent strip (a roof: two quads meeting at a ridge) and a quad turned over, as
    separate casters: grouped by shared corners, sides cancel across them."""
    roof_a = np.array([[0.0, 1, 0], [1, 1.5, 0], [1, 1.5, 1], [0, 1, 1]])
    roof_b = np.array([[1.0, 1.5, 0], [2, 1, 0], [2, 1, 1], [1, 1.5, 1]])
    below = np.array([[0.0, 1, 0], [0, 0, 0], [0, 0, 1], [0, 1, 1]])      # a wall, turned
    far = QUAD + [5.0, 0.0, 0.0]
    parts = [(roof_a, np.array([[0, 1, 2], [0, 2, 3]])),
             (roof_b, np.array([[0, 2, 1], [0, 3, 2]])),   # wound the other way
             (below, np.array([[0, 1, 2], [0, 2, 3]])),
             (far, np.array([[0, 1, 2], [0, 2, 3]]))]
    assert open_caster_groups([p[0] for p in parts]) == [[0, 1, 2], [3]]
    light = light_homogeneous("point", (0.7, 4.0, 0.4), None)
    merged = open_volume(parts[:3], light, 0.05)
    every = [per_triangle_volume(v, f, light, 0.05) for v, f in parts[:3]]
    assert len(merged.faces) < sum(len(v.faces) for v in every)
    assert _unmatched_edges(merged) == 0           # closed, edge for edge
    assert all(_unmatched_edges(v) == 0 for v in every)
    rng = np.random.default_rng(2)
    points = np.concatenate([rng.uniform([-1.0, -3.0, -1.0], [3.0, 1.4, 2.0], (300, 3)),
                             # under the ridge, where the two roof quads' caps start apart
                             rng.uniform([0.95, 1.42, 0.2], [1.05, 1.5, 0.8], (300, 3))])
    got = [_count(merged, p) for p in points]
    want = [sum(_count(v, p) for v in every) for p in points]
    assert got == want
    assert max(want) >= 2                          # overlapping volumes are counted too


@pytest.mark.gl
@pytest.mark.parametrize("preset", ["cornell", "fail-open-caster", "transparency",
                                    "lecture", "shadows-colored"])
def test_the_stencil_is_the_per_triangle_volumes_stencil(gl_ctx, monkeypatch, preset):
    """Every light's stencil mask equals the mask of per-triangle volumes, pixel for pixel,
    with fewer volume triangles where a preset has open casters."""
    from shadelab.raster import shadows
    from shadelab.raster.offscreen import shared_renderer, shared_target

    scene = load_preset(preset, ["render.shadows=volumes"])
    renderer = shared_renderer()
    target = shared_target((320, 240))

    def triangles():
        meshes = renderer.sync(scene)
        return sum(len(v.volume.faces)
                   for i, light in enumerate(scene.active_lights())
                   for v in renderer.shadow_volumes.volumes(scene, meshes, i, light))

    merged = shadows.shadow_masks(renderer, scene, target)
    merged_triangles = triangles()

    def per_triangle(parts, light, offset):
        vertices = np.concatenate([v for v, _ in parts])
        starts = np.cumsum([0] + [len(v) for v, _ in parts[:-1]])
        faces = np.concatenate([f + s for (_, f), s in zip(parts, starts, strict=True)])
        return per_triangle_volume(vertices, faces, light, offset)

    monkeypatch.setattr(shadows, "open_volume", per_triangle)
    renderer.shadow_volumes.release_volumes()
    every = shadows.shadow_masks(renderer, scene, target)
    every_triangles = triangles()
    renderer.shadow_volumes.release_volumes()
    assert merged.any()
    np.testing.assert_array_equal(merged, every)
    if preset in ("cornell", "fail-open-caster"):
        assert merged_triangles < every_triangles
