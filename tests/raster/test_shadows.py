"""Stencil shadow volumes against an independent CPU oracle (embreex shadow rays).

The oracle casts a primary ray through every pixel centre (the rasterizer's sample point),
then a shadow ray from the hit towards each light; the GL side reads the stencil count of each
light's volumes. They must agree on >= 99.5 % of the pixels where S_i matters: pixels whose
visible face (turned towards the eye) faces the light. Elsewhere the diffuse and specular terms
are 0 whatever S_i is, and the oracle's own ray would start inside the surface.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from trimesh.ray.ray_pyembree import RayMeshIntersector

from shadelab.geometry.mesh import scene_bounds, scene_meshes
from shadelab.scene import load_preset
from shadelab.scene.camera import primary_rays
from shadelab.scene.model import Light

SIZE = (160, 120)
AGREEMENT = 0.995

pytestmark = pytest.mark.gl


def oracle_masks(scene) -> tuple[np.ndarray, np.ndarray]:
    """(L, H, W) shadowed-by-ray masks and the (L, H, W) pixels where S_i matters."""
    meshes = scene_meshes(scene)
    diag = float(np.linalg.norm(np.ptp(scene_bounds(meshes), axis=0)))
    every = trimesh.util.concatenate([trimesh.Trimesh(m.vertices, m.faces, process=False)
                                      for m in meshes])
    normals = np.concatenate([m.face_normals for m in meshes])
    casters = [m for m in meshes if scene.objects[m.index].cast_shadows]
    blockers = RayMeshIntersector(trimesh.util.concatenate(
        [trimesh.Trimesh(m.vertices, m.faces, process=False) for m in casters]))
    w, h = SIZE
    origins, dirs = primary_rays(scene.camera, w, h)
    origins, dirs = origins.reshape(-1, 3), dirs.reshape(-1, 3)
    faces, _, points = RayMeshIntersector(every).intersects_id(
        origins, dirs, multiple_hits=False, return_locations=True)
    hit = np.zeros(len(origins), bool)
    hit[_] = True
    position = np.zeros_like(origins)
    position[_] = points
    n = np.zeros_like(origins)
    n[_] = normals[faces]
    n *= np.where(np.einsum("ij,ij->i", n, dirs) > 0.0, -1.0, 1.0)[:, None]
    shadowed, matters = [], []
    for light in scene.active_lights():
        if light.kind == "directional":
            d = -np.asarray(light.direction, float)
            to_light = np.broadcast_to(d / np.linalg.norm(d), position.shape).copy()
            distance = np.full(len(position), np.inf)
        else:
            delta = np.asarray(light.position, float) - position
            distance = np.linalg.norm(delta, axis=1)
            to_light = delta / np.maximum(distance, 1e-30)[:, None]
        faces_light = hit & (np.einsum("ij,ij->i", n, to_light) > 1e-6)
        start = position + 1e-5 * diag * n
        idx = np.flatnonzero(faces_light)
        blocked = np.zeros(len(position), bool)
        tri, ray, loc = blockers.intersects_id(start[idx], to_light[idx], multiple_hits=False,
                                               return_locations=True)
        along = np.linalg.norm(loc - start[idx][ray], axis=1)
        blocked[idx[ray[along < distance[idx][ray]]]] = True
        shadowed.append(blocked.reshape(h, w))
        matters.append(faces_light.reshape(h, w))
    return np.array(shadowed), np.array(matters)


def pixel_surfaces(scene, index: int, thresholds: bool = False):
    """Object ``index`` as the camera sees it, per pixel centre (Embree primary rays): the
    flat pixel numbers, world positions, interpolated (Phong) normals and face normals of the
    hits on the side the camera sees (``thresholds``: and each hit's terminator threshold,
    :func:`shadelab.geometry.normals.threshold_at`)."""
    from trimesh.triangles import points_to_barycentric

    meshes = scene_meshes(scene)
    mesh = meshes[index]
    w, h = SIZE
    origins, dirs = primary_rays(scene.camera, w, h)
    origins, dirs = origins.reshape(-1, 3), dirs.reshape(-1, 3)
    every = trimesh.util.concatenate([trimesh.Trimesh(m.vertices, m.faces, process=False)
                                      for m in meshes])
    first = sum(len(m.faces) for m in meshes[:index])
    tri, ray, loc = RayMeshIntersector(every).intersects_id(
        origins, dirs, multiple_hits=False, return_locations=True)
    on = (tri >= first) & (tri < first + len(mesh.faces))
    tri, ray, loc = tri[on] - first, ray[on], loc[on]
    bary = points_to_barycentric(mesh.triangles[tri], loc)
    normal = np.einsum("rc,rck->rk", bary, mesh.corner_normals[tri])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    front = np.einsum("rk,rk->r", normal, dirs[ray]) < 0.0
    out = ray[front], loc[front], normal[front], mesh.face_normals[tri[front]]
    if thresholds:
        from shadelab.geometry.normals import threshold_at

        tri, bary = tri[front], bary[front]
        out += (threshold_at(mesh.corner_terminators[tri], mesh.corner_normals[tri], bary),)
    return out


def gl_masks(scene) -> np.ndarray:
    from shadelab.raster.offscreen import shared_renderer, shared_target
    from shadelab.raster.shadows import shadow_masks

    return shadow_masks(shared_renderer(), scene, shared_target(SIZE))


def agreement(scene) -> tuple[float, int]:
    expected, matters = oracle_masks(scene)
    got = gl_masks(scene)
    assert got.shape == expected.shape
    same = (got == expected) & matters
    return same.sum() / max(matters.sum(), 1), int(matters.sum())


def inside_volume_scene(method: str):
    """The camera sits inside the sphere's shadow volume, looking down along the shadow."""
    scene = load_preset("shadows", [f"render.shadow_method={method}"])
    light = np.asarray(scene.lights[0].position)
    centre = np.array([-1.0, 0.8, 0.0])
    d = (centre - light) / np.linalg.norm(centre - light)
    eye = centre + 0.95 * d
    scene.camera.eye = tuple(eye)
    scene.camera.target = tuple(eye + 3.0 * d + np.array([-4.0, 0.0, -4.0]))  # shadow and light
    scene.camera.near = 0.01
    return scene


def test_camera_really_inside_the_volume():
    scene = inside_volume_scene("zfail")
    eye = np.asarray(scene.camera.eye)
    light = np.asarray(scene.lights[0].position)
    mesh = trimesh.creation.icosphere(3, 0.8)
    mesh.apply_translation([-1.0, 0.8, 0.0])
    hit = mesh.ray.intersects_any([eye], [(light - eye) / np.linalg.norm(light - eye)])
    assert hit[0] and not mesh.contains([eye])[0]


@pytest.mark.parametrize("preset, overrides", [
    ("shadows", []),
    ("shadows", ["render.shadow_method=zpass"]),
    ("shadows-colored", []),
    ("cornell", ["render.shadows=volumes"]),
])
def test_stencil_mask_matches_shadow_rays(gl_ctx, preset, overrides):
    scene = load_preset(preset, overrides)
    share, counted = agreement(scene)
    assert counted > 0.2 * SIZE[0] * SIZE[1] * len(scene.active_lights())
    assert share >= AGREEMENT, f"{preset}: {share:.4%} of {counted} pixels agree"


def test_eye_inside_volume_zfail_agrees_zpass_fails(gl_ctx):
    scene = inside_volume_scene("zfail")
    expected, matters = oracle_masks(scene)
    assert 0.05 < (expected & matters).sum() / matters.sum() < 0.95  # both shadow and light
    share, counted = agreement(scene)
    assert counted > 5000
    assert share >= AGREEMENT, f"z-fail inside a volume: {share:.4%}"
    zpass, _ = agreement(inside_volume_scene("zpass"))
    assert zpass < 0.9, f"z-pass should break with the eye inside a volume: {zpass:.4%}"


def test_two_overlapping_lights(gl_ctx):
    scene = load_preset("shadows")
    scene.lights.append(Light(kind="point", position=(-2.0, 4.0, 2.5), Ip=(0.5, 0.5, 0.9)))
    expected, matters = oracle_masks(scene)
    both = (expected[0] & expected[1] & matters[0] & matters[1]).sum()
    assert both > 0 and (expected[0] != expected[1]).sum() > 200  # overlapping, not equal
    share, _ = agreement(scene)
    assert share >= AGREEMENT


def _flipped_box_obj(path) -> None:
    box = trimesh.creation.box(extents=(1.0, 1.4, 1.0))
    faces = box.faces.copy()
    faces[::3] = faces[::3, ::-1]  # every third triangle wound the other way
    lines = [f"v {x} {y} {z}" for x, y, z in box.vertices]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces]
    path.write_text("\n".join(lines) + "\n")


def test_inconsistently_wound_caster(gl_ctx, tmp_path):
    from shadelab.geometry.silhouette import light_homogeneous, shadow_volume

    _flipped_box_obj(tmp_path / "box.obj")
    scene = load_preset("shadows", ["objects.2.shape=mesh", f"objects.2.path={tmp_path}/box.obj"])
    mesh = scene_meshes(scene)[2]
    volume = shadow_volume(mesh.vertices, mesh.faces,
                           light_homogeneous("point", scene.lights[0].position, None))
    assert volume.method == "per-triangle"
    share, counted = agreement(scene)
    assert share >= AGREEMENT, f"{share:.4%} of {counted}"


def test_shadowed_frame_is_ambient_where_masked_and_unchanged_elsewhere(gl_ctx):
    from shadelab.raster.offscreen import render_image

    scene = load_preset("shadows", ["render.shadows=none"])
    lit = render_image(scene, SIZE)
    scene.lights[0].enabled = False
    ambient = render_image(scene, SIZE)
    scene.lights[0].enabled = True
    scene.render.shadows = "volumes"
    shadowed = render_image(scene, SIZE)
    mask = gl_masks(scene)[0] & (ambient.sum(axis=2) > 0.0)  # covered pixels
    assert 0.01 < mask.mean() < 0.5
    assert np.abs(shadowed[mask] - ambient[mask]).max() < 1e-5
    # the smooth sphere's terminator band (N.L < 2t) fades S_i (tests/raster/test_terminator.py):
    # there the light's term is scaled by the fade, everywhere else it is left as it was
    ray, position, normal, _, t = pixel_surfaces(scene, 1, thresholds=True)
    to_light = np.asarray(scene.lights[0].position, float) - position
    to_light /= np.linalg.norm(to_light, axis=1, keepdims=True)
    band = np.zeros(mask.size, bool)
    band[ray[np.einsum("rk,rk->r", normal, to_light) < 2.0 * t]] = True
    band = band.reshape(mask.shape)
    assert 0 < band.sum() < 0.02 * band.size
    keep = ~mask & ~band
    assert np.abs(shadowed[keep] - lit[keep]).max() < 2e-3
    fade = ~mask & band
    assert np.all(shadowed[fade] <= lit[fade] + 1e-5)   # the fade only ever takes light away
    assert math.isclose(float(np.median(np.abs(shadowed[keep] - lit[keep]))), 0.0,
                        abs_tol=1e-5)


def test_cli_teaching_flags_change_the_frame(gl_ctx, tmp_path):
    from shadelab.cli import main

    out = {}
    for name, flags in (("plain", []), ("volumes", ["--show-volumes"]),
                        ("silhouettes", ["--show-silhouettes"]),
                        ("heatmap", ["--stencil-heatmap"])):
        code = main(["render", "shadows", "-o", str(tmp_path / f"{name}.png"), "--size", "64x48",
                     "--npy", str(tmp_path / f"{name}.npy"), *flags])
        assert code == 0
        out[name] = np.load(tmp_path / f"{name}.npy")
    for name in ("volumes", "silhouettes", "heatmap"):
        changed = np.abs(out[name] - out["plain"]).max(axis=2) > 1e-3
        assert 0.001 < changed.mean() < 0.9, name


def test_cli_rejects_unknown_shadow_method(capsys):
    from shadelab.cli import main

    code = main(["render", "shadows", "-o", "x.png", "--shadow-method", "zmaybe"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "zmaybe" in err[0]
