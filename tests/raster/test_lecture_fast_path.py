"""The lecture frame's cheaper passes (issue 25): back-face culling of closed meshes seen from
outside, and shadow volumes counted with fans for caps (silhouette.CountVolume). Both must
leave the image as it was: culling only where every back face is hidden behind a front face
of its own mesh, fans only where the stencil counts are the same."""

from __future__ import annotations

import contextlib
import dataclasses

import numpy as np
import pytest
import trimesh

import shadelab.raster.renderer as renderer_module
import shadelab.raster.shadows as shadows_module
from shadelab.geometry.silhouette import (
    away_from_light,
    bounded_volume,
    count_volume,
    is_convex,
    light_homogeneous,
    open_volume,
    shadow_volume,
    volume_sources,
)
from shadelab.gl.target import RenderTarget
from shadelab.raster.renderer import Renderer, _closed_outward
from shadelab.scene.preset import load_preset

SIZE = (160, 120)
PLASTIC_CENTRE = [0.0, 0.7, 0.8]   # lecture's plastic sphere (radius 0.7)


def _frame(ctx, scene, renderer=None):
    """(image, stencil) of one frame (the stencil: the last light's count)."""
    own = renderer is None
    renderer = renderer or Renderer(ctx)
    target = RenderTarget(ctx, SIZE)
    try:
        renderer.render(scene, target, scene.render.shading)
        return target.read(), target.read_stencil()
    finally:
        target.release()
        if own:
            renderer.release()


# ------------------------------------------------------------------ back-face culling
@pytest.mark.gl
@pytest.mark.parametrize("preset, overrides", [
    ("lecture", []), ("lecture", ["render.shadows=none"]), ("lecture", ["render.shading=flat"]),
    ("shadows", []), ("shadows-colored", []), ("cornell-spheres", []), ("multi-lights", []),
])
def test_culling_back_faces_keeps_the_image(gl_ctx, monkeypatch, preset, overrides):
    monkeypatch.setattr(renderer_module, "BACK_FACE_CULLING", False)
    every_face, _ = _frame(gl_ctx, load_preset(preset, overrides))
    monkeypatch.setattr(renderer_module, "BACK_FACE_CULLING", True)
    renderer = Renderer(gl_ctx)
    try:
        culled, _ = _frame(gl_ctx, load_preset(preset, overrides), renderer)
        assert renderer._culled, "the closed meshes of the scene are drawn culled"
    finally:
        renderer.release()
    np.testing.assert_array_equal(culled, every_face)


@pytest.mark.gl
def test_no_culling_with_the_eye_inside_a_closed_mesh(gl_ctx, monkeypatch):
    inside = load_preset("lecture", [f"camera.eye={PLASTIC_CENTRE}",
                                     "camera.target=[0.0, 0.7, -3.0]"])
    renderer = Renderer(gl_ctx)
    try:
        image, _ = _frame(gl_ctx, inside, renderer)
        sphere = renderer._gpu[3]           # the plastic sphere, around the eye
        assert not renderer.cullable(sphere, inside, SIZE)
        assert renderer.cullable(renderer._gpu[2], inside, SIZE)   # the others stay culled
    finally:
        renderer.release()
    monkeypatch.setattr(renderer_module, "BACK_FACE_CULLING", False)
    every_face, _ = _frame(gl_ctx, inside)
    np.testing.assert_array_equal(image, every_face)
    # the check matters: culled anyway, the sphere's inside (all back faces) disappears
    monkeypatch.setattr(renderer_module, "BACK_FACE_CULLING", True)
    monkeypatch.setattr(renderer_module, "eye_outside", lambda *args: True)
    wrong, _ = _frame(gl_ctx, inside)
    assert np.abs(wrong - every_face).max() > 0.01


@pytest.mark.gl
def test_the_near_plane_counts_as_inside(gl_ctx):
    """An eye just outside the box, closer than the near plane reaches, could see the near
    plane cut a front face away: not culled."""
    scene = load_preset("lecture")
    renderer = Renderer(gl_ctx)
    try:
        _frame(gl_ctx, scene, renderer)
        sphere = renderer._gpu[3]
        reach = renderer_module.near_reach(scene, SIZE)
        box_top = float(sphere.bounds[1][1])
        scene.camera = dataclasses.replace(scene.camera,
                                           eye=(0.0, box_top + 0.5 * reach, 0.8))
        assert not renderer.cullable(sphere, scene, SIZE)
        scene.camera = dataclasses.replace(scene.camera,
                                           eye=(0.0, box_top + 2.0 * reach, 0.8))
        assert renderer.cullable(sphere, scene, SIZE)
    finally:
        renderer.release()


def test_only_closed_meshes_wound_outward_are_culled():
    sphere = trimesh.creation.icosphere(subdivisions=2)
    v, f = np.asarray(sphere.vertices), np.asarray(sphere.faces)
    assert _closed_outward(v, f)
    assert not _closed_outward(v, f[:, ::-1])             # inside out: front faces are CW
    assert not _closed_outward(v, f[:-3])                 # open
    quad = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    assert not _closed_outward(quad, np.array([[0, 1, 2], [0, 2, 3]]))


@pytest.mark.gl
def test_cornell_room_is_never_culled(gl_ctx):
    scene = load_preset("cornell")
    renderer = Renderer(gl_ctx)
    try:
        _frame(gl_ctx, scene, renderer)
        for gpu in renderer._gpu.values():
            eye = np.asarray(scene.camera.eye)
            if np.all(eye >= gpu.bounds[0]) and np.all(eye <= gpu.bounds[1]):
                assert id(gpu) not in renderer._culled
    finally:
        renderer.release()


# ------------------------------------------------------------------ count volumes (CPU)
def _finite(vertices4: np.ndarray, light: np.ndarray, distance: float) -> np.ndarray:
    """Homogeneous volume vertices in 3-D: points at infinity (w = 0) moved ``distance``
    from the light along their direction (on the same ray as the volume's own)."""
    out = vertices4[:, :3].copy()
    far = vertices4[:, 3] == 0.0
    origin = light[:3] if light[3] != 0.0 else np.zeros(3)
    out[far] = origin + distance * vertices4[far, :3]
    return out


def _winding(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Winding numbers of a closed triangle surface around ``points`` (solid angles, Van
    Oosterom and Strackee), rounded."""
    total = np.zeros(len(points))
    for start in range(0, len(triangles), 2048):
        tri = triangles[start:start + 2048]
        a = tri[None, :, 0] - points[:, None]
        b = tri[None, :, 1] - points[:, None]
        c = tri[None, :, 2] - points[:, None]
        la, lb, lc = (np.linalg.norm(x, axis=2) for x in (a, b, c))
        det = np.einsum("pti,pti->pt", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("pti,pti->pt", a, b) * lc
               + np.einsum("pti,pti->pt", a, c) * lb + np.einsum("pti,pti->pt", b, c) * la)
        total += 2.0 * np.arctan2(det, den).sum(axis=1)
    winding = total / (4.0 * np.pi)
    assert np.abs(winding - np.round(winding)).max() < 1e-3
    return np.round(winding).astype(int)


def _counts(volume_vertices, faces, light, points) -> np.ndarray:
    return _winding(points, _finite(volume_vertices, light, 1e4)[faces])


def _torus() -> trimesh.Trimesh:
    return trimesh.creation.torus(major_radius=1.0, minor_radius=0.35, major_sections=32,
                                  minor_sections=16)


CASTERS = {
    "sphere": lambda: trimesh.creation.icosphere(subdivisions=3, radius=0.7),
    "capsule": lambda: trimesh.creation.capsule(height=1.0, radius=0.4, count=[24, 24]),
    "torus": _torus,   # not convex: its near cap stays, the far cap becomes a fan
}


def _inside_convex(mesh: trimesh.Trimesh, points: np.ndarray, margin: float) -> np.ndarray:
    """Points within ``margin`` of the inside of a convex mesh (behind every face plane)."""
    normals = np.asarray(mesh.face_normals)
    offsets = np.einsum("ij,ij->i", normals, np.asarray(mesh.triangles)[:, 0])
    return (points @ normals.T - offsets).max(axis=1) < margin


@pytest.mark.parametrize("caster", sorted(CASTERS))
@pytest.mark.parametrize("light", [("point", (2.5, 5.0, 2.0)), ("point", (-3.0, 1.0, 0.5)),
                                   ("directional", (-0.3, -1.0, -0.2))])
def test_count_volume_has_the_full_volumes_counts(caster, light, np_rng):
    mesh = CASTERS[caster]()
    v, f = np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64)
    kind, value = light
    homogeneous = light_homogeneous(kind, value, value)
    full = shadow_volume(v, f, homogeneous)
    convex = is_convex(v, f)
    assert convex == (caster != "torus")
    reduced = count_volume(full, homogeneous, convex)
    assert reduced is not None
    assert len(reduced.faces) < 0.7 * len(full.faces)
    # points all around, in the shadow and out of it, the eye's and the receivers' places;
    # with the near fan, points inside the caster are left out (never seen from outside)
    points = np.concatenate([np_rng.uniform(-4.0, 4.0, (1500, 3)),
                             np_rng.uniform(-1.5, 1.5, (500, 3)) - 1.5 * homogeneous[:3]
                             / np.linalg.norm(homogeneous[:3])])
    if convex:
        points = points[~_inside_convex(mesh, points, 1e-6)]
    before = _counts(full.vertices, full.faces, homogeneous, points)
    assert (before != 0).sum() > 20, "some points lie in the shadow"
    for eye_outside in (True, False):
        faces = np.concatenate([reduced.faces[first:first + count]
                                for first, count in reduced.ranges(eye_outside)])
        np.testing.assert_array_equal(
            _counts(reduced.vertices, faces, homogeneous, points), before)


def test_count_volume_keeps_the_caps_with_the_light_inside_or_no_gain():
    mesh = trimesh.creation.icosphere(subdivisions=2, radius=1.0)
    light = light_homogeneous("point", (0.1, 0.0, 0.0), (0, 0, 0))
    full = shadow_volume(np.asarray(mesh.vertices), np.asarray(mesh.faces), light)
    assert count_volume(full, light, True) is None
    box = trimesh.creation.box(extents=(1.0, 1.4, 1.0))     # 6 silhouette edges, 6 dark faces
    light = light_homogeneous("point", (2.5, 5.0, 2.0), (0, 0, 0))
    full = shadow_volume(np.asarray(box.vertices), np.asarray(box.faces), light)
    assert count_volume(full, light, True) is None


def test_count_volume_with_the_eye_inside_the_caster_uses_the_near_cap(np_rng):
    """Inside a convex caster the fan would count its inside as shadow: ranges(False)
    draws the near cap, and gives the full volume's counts there too."""
    mesh = trimesh.creation.icosphere(subdivisions=3, radius=0.7)
    v, f = np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64)
    light = light_homogeneous("point", (2.5, 5.0, 2.0), (0, 0, 0))
    full = shadow_volume(v, f, light)
    reduced = count_volume(full, light, True)
    points = np_rng.uniform(-0.69, 0.69, (800, 3)) / np.sqrt(3.0)      # inside the sphere
    before = _counts(full.vertices, full.faces, light, points)
    inside_faces = np.concatenate([reduced.faces[a:a + n] for a, n in reduced.ranges(False)])
    np.testing.assert_array_equal(_counts(reduced.vertices, inside_faces, light, points),
                                  before)
    outside_faces = np.concatenate([reduced.faces[a:a + n] for a, n in reduced.ranges(True)])
    assert (_counts(reduced.vertices, outside_faces, light, points) != before).any()


# ------------------------------------------------------------------ count volumes (GL)
def _caster_pixels(ctx, scene) -> np.ndarray:
    """Pixels where a closed caster (the spheres, the box) is the visible surface, grown by
    one pixel: found by recolouring their materials."""
    before, _ = _frame(ctx, scene)
    recoloured = load_preset("lecture", [])
    recoloured.camera = scene.camera
    for name in ("matte", "plastic", "metal", "box"):
        recoloured.materials[name].Od = (0.0, 1.0, 0.0)
        recoloured.materials[name].ka = 1.0
    after, _ = _frame(ctx, recoloured)
    mask = np.abs(after - before).max(axis=-1) > 0
    grown = mask.copy()
    grown[1:] |= mask[:-1]
    grown[:-1] |= mask[1:]
    grown[:, 1:] |= mask[:, :-1]
    grown[:, :-1] |= mask[:, 1:]
    return grown


@pytest.mark.gl
@pytest.mark.parametrize("eye", [
    None,                        # the lecture's camera
    "[-2.5, 0.3, 3.5]",          # low: the dark sides of the spheres in view
    "[1.465, -1.0, -0.907]",     # under the floor, in the metal sphere's volume
    f"{PLASTIC_CENTRE}",         # inside the plastic sphere
    "[-0.9, 0.5, -1.7]",         # inside the box
])
@pytest.mark.parametrize("method", ["zfail", "zpass"])
def test_fans_count_as_the_full_caps(gl_ctx, monkeypatch, eye, method):
    overrides = [f"render.shadow_method={method}"] + ([f"camera.eye={eye}"] if eye else [])
    scene = load_preset("lecture", overrides)
    monkeypatch.setattr(shadows_module, "REDUCED_CAPS", False)
    image_full, full = _frame(gl_ctx, scene)
    monkeypatch.setattr(shadows_module, "REDUCED_CAPS", True)
    renderer = Renderer(gl_ctx)
    try:
        image, fans = _frame(gl_ctx, scene, renderer)
        volumes = renderer.shadow_volumes._cache.values()
        assert sum(v.counted is not None for v in volumes) == 3   # the spheres
    finally:
        renderer.release()
    casters = _caster_pixels(gl_ctx, scene)
    if eye is None or "-1.0" in eye:
        assert (full != 0).sum() > 50, "the view holds shadow"
    # every receiver pixel counts the same; on the casters' own pixels, the dark sides
    # (depth ties with the full near cap, 0 or 1 by rounding) count 1 with the fan
    np.testing.assert_array_equal(fans[~casters], full[~casters])
    changed = casters & (fans != full)
    assert np.isin(fans[changed], (0, 1)).all()
    np.testing.assert_array_equal(image, image_full)


# ------------------------------------------------------------------ hidden volumes
def wall_vertices() -> np.ndarray:
    x, y = np.meshgrid(np.linspace(-12.0, 12.0, 5), np.linspace(0.0, 8.0, 3))
    return np.stack([x.ravel(), y.ravel(), np.full(x.size, -6.0)], axis=1)


def wall_faces() -> np.ndarray:
    faces = []
    for row in range(2):
        for col in range(4):
            a = row * 5 + col
            faces += [[a, a + 1, a + 6], [a, a + 6, a + 5]]
    return np.array(faces)


def _wall_occluder(eye_light=(3.0, 5.0, 3.0)):
    from shadelab.geometry.silhouette import planar_occluder

    vertices, faces = wall_vertices(), wall_faces()
    normals = np.tile([0.0, 0.0, 1.0], (len(faces), 1))
    floor = np.array([[-12.0, 0.0, -12.0], [12.0, 0.0, 12.0]])    # the lecture's floor
    light = light_homogeneous("point", eye_light, (0, 0, 0))
    return planar_occluder(vertices, faces, normals, light, [floor], 0.035, 1e-9)


def test_a_wall_hides_its_volume_only_where_it_hides_what_lies_behind_it():
    wall = _wall_occluder()
    assert wall is not None
    assert wall.hides_volume_from(np.array([0.0, 4.0, 7.5]), 0.1)      # the lecture's eye
    assert wall.hides_volume_from(np.array([5.0, 1.0, 2.0]), 0.1)
    assert not wall.hides_volume_from(np.array([0.0, 30.0, 7.5]), 0.1)  # sees over the top
    assert not wall.hides_volume_from(np.array([20.0, 4.0, 0.0]), 0.1)  # round the side
    assert not wall.hides_volume_from(np.array([0.0, 4.0, -8.0]), 0.1)  # behind it
    assert not wall.hides_volume_from(np.array([0.0, 4.0, -5.95]), 0.1)  # near plane cuts it
    # a floor reaching below the wall's foot shows under it
    from shadelab.geometry.silhouette import planar_occluder

    deeper = planar_occluder(wall_vertices(), wall_faces(), np.tile([0.0, 0.0, 1.0], (16, 1)),
                             light_homogeneous("point", (3.0, 5.0, 3.0), (0, 0, 0)),
                             [np.array([[-12.0, -0.5, -12.0], [12.0, 0.0, 12.0]])],
                             0.035, 1e-9)
    assert not deeper.hides_volume_from(np.array([0.0, 4.0, 7.5]), 0.1)
    # a light behind the wall: its volume comes forward, towards the eye
    lit_from_behind = _wall_occluder((0.0, 4.0, -9.0))
    assert not lit_from_behind.hides_volume_from(np.array([0.0, 4.0, 7.5]), 0.1)


def test_no_occluder_for_a_caster_that_is_not_flat_or_not_convex():
    from shadelab.geometry.silhouette import planar_occluder

    light = light_homogeneous("point", (3.0, 5.0, 3.0), (0, 0, 0))
    fold = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.5]], float)
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    tri = fold[faces]
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    assert planar_occluder(fold, faces, normals, light, [], 0.01, 1e-9) is None
    # an L of three squares: flat, its outline not convex
    ell = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [1, 1, 0], [2, 1, 0],
                    [0, 2, 0], [1, 2, 0]], float)
    squares = [(0, 1, 4, 3), (1, 2, 5, 4), (3, 4, 7, 6)]
    faces = np.array([f for a, b, c, d in squares for f in ((a, b, c), (a, c, d))])
    normals = np.tile([0.0, 0.0, 1.0], (len(faces), 1))
    assert planar_occluder(ell, faces, normals, light, [], 0.01, 1e-9) is None


@pytest.mark.gl
@pytest.mark.parametrize("eye", [None, "[0.0, 30.0, 7.5]", "[3.0, 1.5, -3.0]"])
def test_leaving_out_hidden_volumes_keeps_the_counts(gl_ctx, monkeypatch, eye):
    scene = load_preset("lecture", [f"camera.eye={eye}"] if eye else [])
    monkeypatch.setattr(shadows_module, "HIDDEN_VOLUMES_LEFT_OUT", False)
    image_all, every = _frame(gl_ctx, scene)
    monkeypatch.setattr(shadows_module, "HIDDEN_VOLUMES_LEFT_OUT", True)
    renderer = Renderer(gl_ctx)
    try:
        view = renderer.render(scene, RenderTarget(gl_ctx, SIZE))
        wall = [v for v in renderer.shadow_volumes._cache.values() if v.occluder is not None]
        assert len(wall) == 1
        assert wall[0].hidden_from(view) == (eye != "[0.0, 30.0, 7.5]")
        image, left_out = _frame(gl_ctx, scene, renderer)
    finally:
        renderer.release()
    np.testing.assert_array_equal(left_out, every)
    np.testing.assert_array_equal(image, image_all)


# ------------------------------------------------------------------ bounded volumes (CPU)
BOX = np.array([[-6.0, 0.0, -6.0], [6.0, 4.0, 6.0]])   # the receivers' box of these casters


def _points_in(box: np.ndarray, rng, count: int) -> np.ndarray:
    return rng.uniform(box[0], box[1], (count, 3))


@pytest.mark.parametrize("caster", sorted(CASTERS))
@pytest.mark.parametrize("light", [("point", (2.5, 3.5, 2.0)), ("point", (-3.0, 1.5, 0.5)),
                                   ("directional", (-0.3, -1.0, -0.2)),
                                   ("directional", (1.0, -0.2, 0.1))])
def test_bounded_volume_counts_as_the_volume_to_infinity(caster, light, np_rng):
    """Cut off at a face of the receivers' box, a volume (full caps, and the count volume's
    fans) winds around every point of the box as often as it did reaching infinity, and its
    far points all lie on that face, beyond the box."""
    mesh = CASTERS[caster]()
    v = np.asarray(mesh.vertices, float) + np.array([0.0, 1.2, 0.0])
    f = np.asarray(mesh.faces, np.int64)
    kind, value = light
    homogeneous = light_homogeneous(kind, value, value)
    full = shadow_volume(v, f, homogeneous)
    reduced = count_volume(full, homogeneous, is_convex(v, f))
    margin = 0.02 * float(np.linalg.norm(np.ptp(BOX, axis=0)))
    # points all over the box, and many behind the caster from the light (in its shadow)
    beyond = v[np_rng.integers(0, len(v), 1500)]
    beyond = beyond + np_rng.uniform(0.0, 6.0, (len(beyond), 1)) * away_from_light(
        beyond, homogeneous) + np_rng.normal(0.0, 0.1, beyond.shape)
    points = np.concatenate([_points_in(BOX, np_rng, 1000), beyond])
    points = points[np.all((points > BOX[0]) & (points < BOX[1]), axis=1)]
    points = points[~_inside_convex(mesh, points - [0.0, 1.2, 0.0], 1e-6)] \
        if caster != "torus" else points
    n = len(full.vertices) // 2
    fans = np.concatenate([reduced.faces[a:a + k] for a, k in reduced.ranges(True)])
    for vertices, faces, rows in ((full.vertices, full.faces, volume_sources(n)),
                                  (reduced.vertices, fans, volume_sources(n, True))):
        # (infinity as 1e6 away: a directional light's rays stay parallel to 1e-5 here)
        before = _winding(points, _finite(vertices, homogeneous, 1e6)[faces])
        assert (before != 0).sum() > 20, "some points of the box lie in the shadow"
        cut = bounded_volume(vertices, rows, BOX, margin)
        assert cut is not None
        bounded, face, reach = cut
        assert (bounded[:, 3] == 1.0).all()
        axis, side = divmod(face, 2)
        far = vertices[:, 3] == 0.0
        level = BOX[side, axis] + (margin if side else -margin)
        np.testing.assert_allclose(bounded[far, axis], level)
        assert 0.0 < reach < 1e3
        np.testing.assert_array_equal(_counts(bounded, faces, homogeneous, points), before)


def test_a_caster_on_the_floor_is_cut_off_past_its_moved_caps(np_rng):
    """A box standing on the receivers' floor, counted as an open caster: the caps moved
    along the rays (up to GRAZING_LIMIT offsets, where the light grazes its sides) reach
    below the floor. The cut's plane moves out to half a margin past them (cornell's
    blocks), and every point of the box keeps its count."""
    margin = 0.02 * float(np.linalg.norm(np.ptp(BOX, axis=0)))
    block = trimesh.creation.box(extents=(1.0, 1.6, 1.0))
    block.apply_translation([0.4, BOX[0, 1] + 0.8, -0.3])       # its bottom on the floor
    v, f = np.asarray(block.vertices, float), np.asarray(block.faces, np.int64)
    homogeneous = light_homogeneous("point", (0.2, BOX[1, 1] - 0.5, 0.1), (0, 0, 0))
    volume = open_volume([(v, f)], homogeneous, margin / 20.0)
    near = volume.vertices[volume.vertices[:, 3] == 1.0]
    below = BOX[0, 1] - near[:, 1]
    assert below.max() > 0.5 * margin, "a moved cap reaches past half a margin"
    n = len(volume.vertices) // 2
    cut = bounded_volume(volume.vertices, volume_sources(n), BOX, margin)
    assert cut is not None
    bounded, face, _ = cut
    assert face == 2 * 1 + 0                                    # the floor's face
    far = volume.vertices[:, 3] == 0.0
    plane = BOX[0, 1] - (below.max() + 0.5 * margin)
    np.testing.assert_allclose(bounded[far, 1], plane)
    assert BOX[0, 1] - 2.0 * margin <= plane < BOX[0, 1] - margin
    points = np.concatenate([_points_in(BOX, np_rng, 1500),
                             v[np_rng.integers(0, len(v), 500)] * [1.0, 0.0, 1.0]
                             + [0.0, BOX[0, 1] + 1e-3, 0.0]
                             + np_rng.normal(0.0, 0.6, (500, 3)) * [1.0, 0.0, 1.0]])
    points = points[np.all((points > BOX[0]) & (points < BOX[1]), axis=1)]
    before = _winding(points, _finite(volume.vertices, homogeneous, 1e6)[volume.faces])
    assert (before != 0).sum() > 20, "some points of the floor lie in the shadow"
    np.testing.assert_array_equal(_counts(bounded, volume.faces, homogeneous, points), before)


def test_bounded_volume_refuses_rays_no_face_of_the_box_catches():
    """A light close to a wide plate facing the box's diagonal sends rays out through
    three faces, none crossed by all of them: no cut (counted to infinity); a plate
    reaching beyond the box gets none either."""
    diagonal = np.ones(3) / np.sqrt(3.0)
    plate = trimesh.creation.box(extents=(5.0, 0.05, 5.0))
    plate.apply_transform(trimesh.geometry.align_vectors([0.0, 1.0, 0.0], diagonal))
    plate.apply_translation(0.3 * diagonal)
    v, f = np.asarray(plate.vertices, float), np.asarray(plate.faces, np.int64)
    box = np.array([[-4.0, -4.0, -4.0], [4.0, 4.0, 4.0]])
    assert np.all(np.abs(v) < 4.0)
    light = light_homogeneous("point", (0.0, 0.0, 0.0), (0, 0, 0))
    volume = shadow_volume(v, f, light)
    n = len(volume.vertices) // 2
    assert bounded_volume(volume.vertices, volume_sources(n), box, 0.1) is None
    far_light = light_homogeneous("point", -20.0 * diagonal, (0, 0, 0))
    volume = shadow_volume(v, f, far_light)
    assert bounded_volume(volume.vertices, volume_sources(n), box, 0.1) is not None
    assert bounded_volume(volume.vertices, volume_sources(n), box / 2.0, 0.1) is None


# ------------------------------------------------------------------ bounded volumes (GL)
@contextlib.contextmanager
def _renderer(ctx):
    renderer = Renderer(ctx)
    try:
        yield renderer
    finally:
        renderer.release()


def _switched(ctx, monkeypatch, module, switch: str, scene, probe):
    """(image with ``module.switch`` False, image with it True, ``probe(renderer)`` of the
    second frame's renderer)."""
    monkeypatch.setattr(module, switch, False)
    off, _ = _frame(ctx, scene)
    monkeypatch.setattr(module, switch, True)
    with _renderer(ctx) as renderer:
        on, _ = _frame(ctx, scene, renderer)
        return off, on, probe(renderer)


@pytest.mark.gl
@pytest.mark.parametrize("preset, overrides", [
    ("lecture", []), ("lecture", ["camera.eye=[1.465, -1.0, -0.907]"]),
    ("lecture", [f"camera.eye={PLASTIC_CENTRE}", "camera.target=[0.0, 0.7, -3.0]"]),
    ("lecture", ["camera.eye=[0.0, 40.0, 60.0]"]), ("shadows", []),
    ("shadows-colored", []), ("mesh-open", []), ("mesh-spot", []), ("mesh-stl", []),
    ("fail-open-caster", []), ("multi-lights", []), ("cornell-spheres", []),
    ("cornell", ["render.shadows=volumes"]),
])
def test_bounded_volumes_keep_the_image(gl_ctx, monkeypatch, preset, overrides):
    """The z-fail count with the volumes cut off at the receivers' box gives the image the
    volumes to infinity give, bit for bit, and on the lecture it is the cut geometry that
    was counted."""
    scene = load_preset(preset, overrides)

    def cut_geometry(renderer):
        shadows = renderer.shadow_volumes
        return (shadows.bounded_for(renderer._view, scene.render.shadow_method),
                [v.bounded_vao is not None for v in shadows._cache.values()])

    to_infinity, image, (used, cut) = _switched(gl_ctx, monkeypatch, shadows_module,
                                                "BOUNDED_VOLUMES", scene, cut_geometry)
    if preset in ("lecture", "cornell") and len(overrides) == (preset == "cornell"):
        assert used and all(cut), "every volume is counted cut off (cornell: its blocks too)"
    np.testing.assert_array_equal(image, to_infinity)


@pytest.mark.gl
def test_bounded_volumes_only_for_zfail_and_fine_depth_steps(gl_ctx):
    scene = load_preset("lecture")
    with _renderer(gl_ctx) as renderer:
        _frame(gl_ctx, scene, renderer)
        shadows, view = renderer.shadow_volumes, renderer._view
        assert shadows.bounded_for(view, "zfail")
        assert not shadows.bounded_for(view, "zpass")     # z-pass keeps its failure
        coarse = dataclasses.replace(view, near=1e-7)      # depth steps of metres out there
        assert not shadows.bounded_for(coarse, "zfail")
        assert not shadows.bounded_for(dataclasses.replace(view, near=0.0), "zfail")


# ------------------------------------------------------------------ one light, lit first
@pytest.mark.gl
@pytest.mark.parametrize("preset, overrides", [
    ("lecture", []), ("lecture", ["render.shading=flat"]), ("lecture", ["render.specular=blinn"]),
    ("lecture", ["render.shadow_method=zpass"]), ("lecture", ["render.shading=gouraud"]),
    ("lecture", [f"camera.eye={PLASTIC_CENTRE}", "camera.target=[0.0, 0.7, -3.0]"]),
    ("cornell", ["render.shadows=volumes"]), ("shadows", []), ("mesh-open", []),
    ("mesh-spot", []), ("mesh-stl", []), ("fail-open-caster", []),
    ("fail-zpass-eye-inside", []),
    ("surface-detail", ["render.shadows=volumes", "lights.1.enabled=false"]),
])
def test_lit_first_keeps_the_image(gl_ctx, monkeypatch, preset, overrides):
    """One light: ambient + light first, the count, ambient over the shadow gives the image
    of the ambient pass, the count and the additive lit pass: bit for bit where the colour is
    shaded per pixel (ambient + x = x + ambient); Gouraud interpolates the sum instead of
    adding two interpolations, equal to float rounding."""
    scene = load_preset(preset, overrides)
    two_passes, image, lit_first = _switched(
        gl_ctx, monkeypatch, renderer_module, "LIT_FIRST", scene,
        lambda renderer: renderer._lit_first(scene, scene.active_lights()))
    assert lit_first
    assert (np.abs(two_passes - np.asarray(scene.render.background)).max(axis=-1) > 0).any()
    if scene.render.shading == "gouraud":
        np.testing.assert_allclose(image, two_passes, rtol=0.0, atol=2e-5)
    else:
        np.testing.assert_array_equal(image, two_passes)


SCISSOR_VIEWS = [
    ("lecture", []), ("lecture", ["camera.eye=[1.465, -1.0, -0.907]"]),
    ("lecture", [f"camera.eye={PLASTIC_CENTRE}", "camera.target=[0.0, 0.7, -3.0]"]),
    ("lecture", ["camera.eye=[0.0, 40.0, 60.0]"]), ("lecture", ["render.shadow_method=zpass"]),
    ("lecture", ["lights.0.position=[-4.0, 2.0, 1.0]"]), ("lecture", ["render.shading=gouraud"]),
    ("shadows", []), ("mesh-open", []), ("mesh-spot", []), ("mesh-stl", []),
    ("fail-open-caster", []), ("cornell-spheres", ["render.shadows=volumes"]),
    ("cornell", ["render.shadows=volumes"]),
]


@pytest.mark.gl
@pytest.mark.parametrize("preset, overrides", SCISSOR_VIEWS)
def test_the_shadow_rectangle_holds_every_counted_pixel(gl_ctx, preset, overrides):
    """ShadowVolumes.screen_rect: every pixel whose count is not 0 lies in it (the stencil
    after the frame is the count); on the lecture it leaves most of the frame out; None only
    where a counted point lies at or behind the eye's plane (the eye under the floor or
    inside a sphere, where no shadow is in view)."""
    scene = load_preset(preset, overrides)
    assert len(scene.active_lights()) == 1
    with _renderer(gl_ctx) as renderer:
        _, stencil = _frame(gl_ctx, scene, renderer)
        shadows = renderer.shadow_volumes
        volumes = shadows.volumes(scene, renderer.sync(scene), 0, scene.active_lights()[0])
        view = renderer._view
        rect = shadows.screen_rect(view, volumes, scene.render.shadow_method)
        bounded = shadows.bounded_for(view, scene.render.shadow_method)
        points = np.vstack([v.count_points(bounded) for v in volumes if not v.hidden_from(view)])
    rows, cols = np.nonzero(stencil)
    shadowless = {"camera.eye=[1.465, -1.0, -0.907]", f"camera.eye={PLASTIC_CENTRE}"}
    if not shadowless & set(overrides):
        assert len(rows) > 0, "the view shows some shadow"
    if rect is None:    # only where a counted point lies at or behind the eye's plane
        assert (points @ view.clip_from_world.T)[:, 3].min() <= 0.0
        assert preset != "lecture" or shadowless & set(overrides)
        return
    x, y, width, height = rect
    up = SIZE[1] - 1 - rows                       # stencil rows run from the top
    if len(rows) == 0:
        return
    assert cols.min() >= x and cols.max() < x + width
    assert up.min() >= y and up.max() < y + height
    if preset == "lecture" and not overrides:
        assert width * height < 0.5 * SIZE[0] * SIZE[1]


@pytest.mark.gl
@pytest.mark.parametrize("preset, overrides", SCISSOR_VIEWS)
def test_the_scissored_shadow_pass_keeps_the_image(gl_ctx, monkeypatch, preset, overrides):
    """The ambient-only pass over the shadow drawn inside screen_rect only: the same image
    bit for bit."""
    scene = load_preset(preset, overrides)
    whole, image, _ = _switched(gl_ctx, monkeypatch, renderer_module, "SCISSOR_SHADOW",
                                scene, lambda renderer: None)
    np.testing.assert_array_equal(image, whole)


@pytest.mark.gl
def test_a_rectangle_that_misses_the_shadow_changes_the_image(gl_ctx, monkeypatch):
    """The scissor is applied: half the lecture's rectangle loses shadow pixels."""
    scene = load_preset("lecture")
    image, _ = _frame(gl_ctx, scene)
    real = shadows_module.ShadowVolumes.screen_rect

    def half(self, *args):
        x, y, width, height = real(self, *args)
        return x + width // 2, y, width - width // 2, height

    monkeypatch.setattr(shadows_module.ShadowVolumes, "screen_rect", half)
    cut, _ = _frame(gl_ctx, scene)
    assert (np.abs(cut - image).max(axis=-1) > 0).sum() > 20


@pytest.mark.gl
def test_lit_first_only_for_one_light_and_opaque_casters(gl_ctx):
    with _renderer(gl_ctx) as renderer:
        lecture = load_preset("lecture")
        assert renderer._lit_first(lecture, lecture.active_lights())
        several = load_preset("shadows-colored")
        assert len(several.active_lights()) > 1
        assert not renderer._lit_first(several, several.active_lights())
        glass = load_preset("lecture", ["materials.plastic.kt=0.5"])
        assert not renderer._lit_first(glass, glass.active_lights())


@pytest.mark.gl
def test_near_first_draws_what_lies_in_front_first(gl_ctx):
    scene = load_preset("lecture")
    with _renderer(gl_ctx) as renderer:
        _frame(gl_ctx, scene, renderer)
        meshes = [renderer._gpu[k] for k in range(len(scene.objects))]
        order = [scene.objects[g.mesh.index].name
                 for g in renderer_module._near_first(meshes, np.asarray(scene.camera.eye))]
    assert order.index("back wall") < order.index("floor")       # the floor reaches behind it
    assert max(order.index(n) for n in ("matte sphere", "plastic sphere", "metal sphere",
                                         "box")) < order.index("back wall")


@pytest.mark.gl
def test_the_lit_pass_variant_fades_on_a_context_with_no_program_yet(gl_ctx):
    """A frame that starts with the lit pass (one light, lit first) compiles the terminator
    variant before any other program: it must still see ShadeLab's lighting chunk and fade
    (it compiled without TERMINATOR, a bright rim on the dark side of the first frame)."""
    scene = load_preset("lecture")
    saved = dict(gl_ctx.includes)
    gl_ctx.includes.clear()
    try:
        with _renderer(gl_ctx) as renderer:
            variant = renderer.programs_for_lights(scene.active_lights(), "phong",
                                                   terminator=True)
        assert variant.defines.get("TERMINATOR") == 1
    finally:
        gl_ctx.includes.clear()
        gl_ctx.includes.update(saved)
