"""Shadow-volume geometry (pure numpy/trimesh): silhouettes, closure, orientation, fallbacks."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from shadelab.geometry.silhouette import light_homogeneous, shadow_volume


def _closed(volume, distance=50.0) -> trimesh.Trimesh:
    vertices, faces = volume.finite(distance)
    return trimesh.Trimesh(vertices, faces, process=False)  # connectivity by index


def test_cube_lit_along_its_diagonal_has_a_six_edge_silhouette_loop():
    cube = trimesh.creation.box()
    volume = shadow_volume(cube.vertices, cube.faces,
                           light_homogeneous("directional", None, (-1.0, -1.0, -1.0)))
    assert volume.method == "silhouette"
    edges = volume.silhouette
    assert len(edges) == 6
    # a single closed loop: every vertex has one outgoing and one incoming edge
    assert sorted(edges[:, 0]) == sorted(edges[:, 1]) and len(set(edges[:, 0])) == 6
    nxt = dict(edges)
    v, seen = edges[0, 0], []
    for _ in range(6):
        seen.append(v)
        v = nxt[v]
    assert v == edges[0, 0] and len(set(seen)) == 6
    # the two corners on the diagonal are not on the silhouette
    corners = cube.vertices[np.unique(edges)]
    assert not np.any(np.all(np.abs(corners - 0.5) < 1e-9, axis=1))
    assert not np.any(np.all(np.abs(corners + 0.5) < 1e-9, axis=1))


@pytest.mark.parametrize("light", [("point", (3.0, 4.0, 2.0), None),
                                   ("directional", None, (0.3, -1.0, 0.2)),
                                   ("spot", (-2.0, 3.0, -1.0), (1.0, -1.0, 0.0))])
@pytest.mark.parametrize("shape", ["box", "sphere", "torus"])
def test_volume_is_watertight_and_outward(shape, light):
    mesh = {"box": trimesh.creation.box(extents=(1.0, 2.0, 0.5)),
            "sphere": trimesh.creation.icosphere(2),
            "torus": trimesh.creation.torus(1.0, 0.3, 16, 8)}[shape]
    volume = shadow_volume(mesh.vertices, mesh.faces, light_homogeneous(*light), offset=0.01)
    assert volume.method == "silhouette"
    closed = _closed(volume)
    assert closed.is_watertight and closed.is_winding_consistent
    assert closed.volume > 0.0  # wound outward, as the stencil counting expects
    assert np.all(volume.vertices[len(volume.vertices) // 2:, 3] == 0.0)  # extruded to w = 0


def test_volume_contains_the_shadow_and_not_the_lit_side():
    sphere = trimesh.creation.icosphere(3)
    light = light_homogeneous("point", (0.0, 5.0, 0.0), None)
    closed = _closed(shadow_volume(sphere.vertices, sphere.faces, light, offset=1e-3))
    inside = closed.contains([[0.0, -2.0, 0.0], [0.0, 1.5, 0.0], [2.0, -2.0, 0.0],
                              [0.0, 0.999, 0.0]])
    assert inside.tolist() == [True, False, False, False]


def test_open_and_inconsistent_casters_get_per_triangle_volumes():
    quad = np.array([[0.0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1]])
    faces = np.array([[0, 1, 2], [0, 3, 2]])  # open, and the second triangle turned over
    light = light_homogeneous("point", (0.5, 3.0, 0.5), None)
    volume = shadow_volume(quad, faces, light, offset=0.01)
    assert volume.method == "per-triangle"
    closed = _closed(volume)
    assert closed.is_winding_consistent and closed.volume > 0.0
    assert closed.body_count == 2 and all(b.is_watertight for b in closed.split())
    assert closed.contains([[0.3, -1.0, 0.6]])[0] and not closed.contains([[0.3, 0.5, 0.6]])[0]
    consistent = shadow_volume(quad, np.array([[0, 1, 2], [0, 2, 3]]), light)
    assert len(consistent.silhouette) == 4  # an open quad shows its outline, not its diagonal

    box = trimesh.creation.box()
    flipped = box.faces.copy()
    flipped[::4] = flipped[::4, ::-1]
    volume = shadow_volume(box.vertices, flipped, light)
    assert volume.method == "per-triangle"
    assert _closed(volume).is_winding_consistent


def test_per_triangle_caps_keep_their_gap_at_grazing_light_and_rays_stay_put():
    quad = np.array([[0.0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1]])
    faces = np.array([[0, 2, 1], [0, 3, 2]])  # normal +y
    light = light_homogeneous("point", (5.0, 0.5, 0.5), None)  # light 6-12 degrees up
    volume = shadow_volume(quad, faces, light, offset=0.01)
    near = volume.vertices[: len(volume.vertices) // 2, :3]
    # a full offset below the plane, though a plain shift along the rays would leave ~0.001
    assert np.allclose(near[:, 1], -0.01, atol=1e-9)
    # and each moved corner stays on the ray from the light through one of the quad's corners
    d_new = (near - light[:3]) / np.linalg.norm(near - light[:3], axis=1, keepdims=True)
    d_old = (quad - light[:3]) / np.linalg.norm(quad - light[:3], axis=1, keepdims=True)
    assert np.all((d_new @ d_old.T).max(axis=1) > 1.0 - 1e-12)


def test_a_box_standing_on_the_floor_shadows_the_floor_right_up_to_its_base():
    """Closed casters' volumes start at the caster itself (the dark cap, no offset): a floor
    point 1e-4 beside the box's shadowed base edge is inside the volume; with the old offset
    of 1e-3 of the scene diagonal (0.03 here) it was outside, a lit sliver along the base."""
    box = trimesh.creation.box(extents=(1.0, 1.0, 1.0))
    vertices = np.asarray(box.vertices) + [0.0, 0.5 + 1e-3, 0.0]     # standing on y = 0
    light = light_homogeneous("point", (3.0, 4.0, 0.5), None)
    volume = shadow_volume(vertices, box.faces, light, offset=0.03)
    assert volume.method == "silhouette"
    solid = _closed(volume)
    assert solid.is_watertight
    beside = [[-0.5 - 1e-4, 1e-4, 0.0], [-0.5 - 1e-3, 1e-4, 0.3]]  # just past the base edge
    lit = [[0.5 + 1e-3, 1e-4, 0.0]]                                 # the light's side
    assert all(_winding(solid, p) > 0.5 for p in beside)
    assert all(abs(_winding(solid, p)) < 0.5 for p in lit)


def _winding(mesh: trimesh.Trimesh, point) -> float:
    """Generalized winding number of a closed mesh about ``point`` (1 inside, 0 outside):
    the signed solid angles of its triangles (Van Oosterom and Strackee) over 4 pi; robust a
    hair's breadth from the surface, where ray-parity tests are not."""
    a, b, c = (mesh.vertices[mesh.faces[:, k]] - np.asarray(point, float) for k in range(3))
    la, lb, lc = (np.linalg.norm(x, axis=1) for x in (a, b, c))
    det = np.einsum("ij,ij->i", a, np.cross(b, c))
    den = (la * lb * lc + np.einsum("ij,ij->i", a, b) * lc + np.einsum("ij,ij->i", b, c) * la
           + np.einsum("ij,ij->i", c, a) * lb)
    return float(np.sum(2.0 * np.arctan2(det, den)) / (4.0 * np.pi))
