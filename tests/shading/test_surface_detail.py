"""Texture-mapped Od and bump maps against numpy on a quad facing the camera (GL)."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from shadelab.raster.textures import srgb_to_linear
from shadelab.scene.camera import primary_rays
from shadelab.scene.model import Camera, Light, Material, Object, Scene

pytestmark = pytest.mark.gl

SIZE = (96, 72)
HALF = 1.0  # the quad spans [-1, 1]^2 in the z = 0 plane, facing +z


def quad_scene(material: Material) -> Scene:
    quad = Object(shape="quad", material="m", normals="flat",
                  vertices=[[-HALF, -HALF, 0.0], [HALF, -HALF, 0.0], [HALF, HALF, 0.0],
                            [-HALF, HALF, 0.0]])
    scene = Scene(Ia=(1.0, 1.0, 1.0), camera=Camera(eye=(0.0, 0.0, 2.0), target=(0, 0, 0),
                                                    fov_y=60.0),
                  materials={"m": material}, objects=[quad])
    return scene


def pixel_uv(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """uv of every pixel centre on the quad (u along +x, v along +y) and the covered mask."""
    origins, dirs = primary_rays(scene.camera, *SIZE)
    t = -origins[..., 2] / dirs[..., 2]
    hit = origins + t[..., None] * dirs
    uv = (hit[..., :2] + HALF) / (2 * HALF)
    inside = np.all((uv > 0.0) & (uv < 1.0), axis=-1)
    return uv, inside


def render(scene: Scene, shading: str) -> np.ndarray:
    from shadelab.raster.offscreen import render_image

    return render_image(scene, SIZE, shading)


@pytest.mark.parametrize("shading", ["flat", "gouraud", "phong"])
def test_checker_matches_uv_cells(gl_ctx, shading):
    m = Material(ka=1.0, kd=0.0, Od=(0.9, 0.8, 0.1), texture="checker", texture_scale=4.0,
                 texture_color2=(0.1, 0.2, 0.7))
    scene = quad_scene(m)
    image = render(scene, shading)
    uv, inside = pixel_uv(scene)
    p = uv * m.texture_scale
    even = (np.floor(p[..., 0]) + np.floor(p[..., 1])) % 2 == 0
    want = np.where(even[..., None], np.asarray(m.Od), np.asarray(m.texture_color2))
    # away from cell borders (a quarter pixel) the cell is unambiguous
    frac = np.abs(p - np.round(p))
    clear = inside & np.all(frac > 0.02, axis=-1)
    assert clear.sum() > 0.5 * inside.sum()
    close = np.abs(image - want).max(axis=-1) < 1e-5
    assert close[clear].mean() >= 0.999, close[clear].mean()


def test_image_texture_is_decoded_to_linear_and_modulates_od(gl_ctx, tmp_path):
    texels = np.array([[[255, 0, 0], [0, 255, 0]], [[0, 0, 255], [128, 128, 128]]], np.uint8)
    Image.fromarray(texels).save(tmp_path / "t.png")
    m = Material(ka=1.0, kd=0.0, Od=(0.5, 1.0, 1.0), texture="t.png", texture_scale=1.0)
    scene = quad_scene(m)
    scene.base_dir = str(tmp_path)
    image = render(scene, "phong")
    uv, _ = pixel_uv(scene)
    # texel centres: the image's top row is v = 0.75 (images are stored top row first)
    for (u, v), rgb in {(0.25, 0.75): texels[0, 0], (0.75, 0.75): texels[0, 1],
                        (0.25, 0.25): texels[1, 0], (0.75, 0.25): texels[1, 1]}.items():
        r, c = np.unravel_index(np.argmin(np.linalg.norm(uv - (u, v), axis=-1)), uv.shape[:2])
        want = np.asarray(m.Od) * srgb_to_linear(rgb / 255.0)
        assert np.abs(image[r, c] - want).max() < 0.03, (u, v, image[r, c], want)


def test_bump_normals_follow_the_height_gradient(gl_ctx):
    k, s = 0.2, 3.0
    m = Material(ka=0.0, kd=1.0, Od=(1.0, 1.0, 1.0), bump="bumps", bump_scale=k,
                 texture_scale=s)
    scene = quad_scene(m)
    scene.lights = [Light(kind="directional", direction=(0.0, 0.0, -1.0), Ip=(1.0, 1.0, 1.0))]
    image = render(scene, "phong")[..., 0]
    uv, inside = pixel_uv(scene)
    x, y = 2 * np.pi * s * uv[..., 0], 2 * np.pi * s * uv[..., 1]
    hx = 0.5 * 2 * np.pi * np.cos(x) * np.sin(y)
    hy = 0.5 * 2 * np.pi * np.sin(x) * np.cos(y)
    want = 1.0 / np.sqrt(1.0 + k * k * (hx * hx + hy * hy))  # N'.L, N' = norm(N - k grad H)
    err = np.abs(image - want)[inside]
    assert want[inside].min() < 0.9  # the bumps really tilt the normals
    assert err.max() < 2e-3, err.max()
    scene.materials["m"].bump = ""
    plain = render(scene, "phong")[..., 0]
    assert np.abs(plain[inside] - 1.0).max() < 1e-5


@pytest.mark.parametrize("shading", ["flat", "gouraud"])
def test_bumps_show_in_flat_and_gouraud_too(gl_ctx, shading):
    m = Material(ka=0.0, kd=1.0, bump="bumps", bump_scale=0.3, texture_scale=2.0)
    scene = quad_scene(m)
    scene.objects[0].segments = 16
    scene.lights = [Light(kind="directional", direction=(0.0, 0.0, -1.0))]
    image = render(scene, shading)
    _, inside = pixel_uv(scene)
    values = image[..., 0][inside]
    assert np.isfinite(values).all() and values.max() <= 1.0 + 1e-5 and values.min() < 0.95


@pytest.mark.parametrize("shading", ["flat", "gouraud", "phong"])
def test_untextured_material_output_is_unchanged(gl_ctx, shading):
    """Materials without texture or bump go through the plain programs: the same pixels."""
    from shadelab.scene import load_preset

    scene = load_preset("surface-detail")
    textured = render(scene, shading)
    plain_scene = load_preset("surface-detail")
    for m in plain_scene.materials.values():
        m.texture, m.bump = "", ""
    plain = render(plain_scene, shading)
    assert np.abs(textured - plain).max() > 0.1  # the detail shows
    # Only the floor is textured now: the wall and sphere pixels match the plain frame.
    scene.materials["bricks"].texture = scene.materials["bricks"].bump = ""
    scene.materials["bumpy"].bump = ""
    only_floor = render(scene, shading)
    floor = np.abs(only_floor - plain).max(axis=-1) > 0.0
    plain_scene.objects = plain_scene.objects[1:]
    without_floor = render(plain_scene, shading)
    objects = without_floor.sum(axis=-1) > 0.0
    assert objects.sum() > 500 and floor.sum() > 500
    assert not (floor & objects).any()
    assert np.array_equal(only_floor[objects], plain[objects])


def test_missing_texture_is_a_one_line_error(tmp_path, capsys):
    from shadelab.cli import main

    code = main(["render", "shadows", "-o", str(tmp_path / "x.png"), "--size", "16x12",
                 "--set", "materials.red.texture=nope.png"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1
    assert "materials.red.texture" in err[0] and "nope.png" in err[0]
