"""The raster renderer: golden images for every preset x shading mode, agreement with the numpy
reference per pixel, and the lecture's qualitative claims made quantitative."""

from __future__ import annotations

import numpy as np
import pytest
from tests.golden import compare_golden

from shadelab.geometry.mesh import scene_meshes
from shadelab.raster.offscreen import render_image
from shadelab.scene.camera import primary_rays
from shadelab.scene.model import Camera, Light, Material, Object, Scene
from shadelab.scene.preset import list_presets, load_preset
from shadelab.shading.conventions import to_srgb8
from shadelab.shading.reference import shade

pytestmark = pytest.mark.gl
GOLDEN_SIZE = (160, 120)


@pytest.mark.parametrize("shading", ["flat", "gouraud", "phong"])
@pytest.mark.parametrize("preset", list_presets())
def test_golden(gl_ctx, preset, shading, update_golden):
    scene = load_preset(preset)
    image = render_image(scene, GOLDEN_SIZE, shading)
    assert np.all(np.isfinite(image))
    compare_golden(f"{preset}-{shading}", to_srgb8(image, scene.render.exposure), update_golden)


def _single(obj: Object, material: Material, lights: list[Light], eye=(0.0, 0.0, 3.0),
            Ia=(0.0, 0.0, 0.0)) -> Scene:
    return Scene(Ia=Ia, camera=Camera(eye=eye, target=(0.0, 0.0, 0.0), fov_y=40.0),
                 lights=lights, materials={"m": material}, objects=[obj])


def test_phong_pixels_match_numpy_reference_on_a_plane(gl_ctx):
    """Every covered pixel of a lit quad equals reference.shade at the ray's hit point."""
    quad = Object(shape="quad", material="m",
                  vertices=[[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]])
    m = Material(ka=0.2, kd=0.6, ks=0.5, n=20.0, Od=(0.9, 0.6, 0.3))
    lights = [Light(position=(0.5, 0.8, 1.5), Ip=(1.0, 0.9, 0.8), attenuation="lecture",
                    c1=0.3, c2=0.2, c3=0.1),
              Light(kind="spot", position=(-0.5, 0.0, 1.0), direction=(0.2, 0.0, -1.0),
                    Ip=(0.3, 0.5, 0.9), cone_angle=35.0, spot_exponent=2.0)]
    scene = _single(quad, m, lights, eye=(0.3, -0.4, 3.0), Ia=(0.2, 0.2, 0.2))
    w, h = 96, 72
    image = render_image(scene, (w, h), "phong")
    origins, dirs = primary_rays(scene.camera, w, h)
    t = -origins[..., 2] / dirs[..., 2]
    points = origins + t[..., None] * dirs
    expected = shade(points, np.array([0.0, 0.0, 1.0]), scene.camera.eye, m, lights, scene.Ia)
    inside = np.all(np.abs(points[..., :2]) < 1.95, axis=-1)
    err = np.abs(image - expected)[inside]
    # Rasterizer interpolation in float32 vs float64 rays: 1e-3 of the pixel's value.
    assert inside.mean() > 0.8
    assert np.quantile(err, 0.999) < 1e-3 and err.max() < 5e-3


def test_gouraud_misses_highlight_inside_large_triangle_phong_catches_it(gl_ctx):
    quad = Object(shape="quad", material="m", segments=1,
                  vertices=[[-2, -2, 0], [2, -2, 0], [2, 2, 0], [-2, 2, 0]])
    m = Material(ka=0.0, kd=0.2, ks=0.8, n=80.0)
    scene = _single(quad, m, [Light(position=(0.0, 0.0, 1.0))], eye=(0.0, 0.0, 3.0))
    phong = render_image(scene, (65, 65), "phong")
    gouraud = render_image(scene, (65, 65), "gouraud")
    centre = (32, 32)  # odd size: the centre pixel's ray hits the quad's centre
    # Phong: N.H = 1 at the centre -> kd + ks = 1.0; Gouraud interpolates corner values (~0.03).
    assert phong[centre].mean() == pytest.approx(1.0, abs=0.02)
    assert gouraud[centre].mean() < 0.1


def test_flat_shading_is_constant_per_face(gl_ctx):
    scene = load_preset("sphere-shading")
    w, h = 120, 120
    image = render_image(scene, (w, h), "flat")
    mesh = scene_meshes(scene)[0]
    m = scene.materials["plastic"]
    centroids = mesh.triangles.mean(axis=1)
    face_colors = shade(centroids, mesh.face_normals, scene.camera.eye, m, scene.lights, scene.Ia)
    covered = image.reshape(-1, 3)[np.abs(image).sum(axis=2).reshape(-1) > 0]
    distance = np.abs(covered[:, None, :] - face_colors[None, :, :]).max(axis=2).min(axis=1)
    assert np.quantile(distance, 0.99) < 1e-4  # each pixel is its face's one color
    distinct = np.unique(np.round(covered, 4), axis=0)
    assert len(distinct) <= len(mesh.faces)


def test_phong_and_blinn_peak_at_same_place_when_light_at_eye(gl_ctx):
    eye = (0.4, 0.3, 3.0)
    sphere = Object(shape="sphere", material="m", subdivisions=5)
    m = Material(ka=0.0, kd=0.0, ks=1.0, n=50.0)
    scene = _single(sphere, m, [Light(position=eye)], eye=eye)
    phong = render_image(scene, (96, 96), "phong", "phong")[..., 0]
    blinn = render_image(scene, (96, 96), "phong", "blinn")[..., 0]
    p = np.unravel_index(np.argmax(phong), phong.shape)
    b = np.unravel_index(np.argmax(blinn), blinn.shape)
    assert abs(p[0] - b[0]) <= 1 and abs(p[1] - b[1]) <= 1
    # the brightest pixel centre lies within a pixel of the exact peak (value 1)
    assert phong.max() > 0.95 and blinn.max() > 0.95
    assert not np.allclose(phong, blinn, atol=0.05)  # same peak, different lobes


def test_gouraud_equals_reference_at_vertices_of_big_triangles(gl_ctx):
    """Gouraud: the reference evaluated at a quad's corners, interpolated linearly over each
    triangle; checked at every pixel centre on the quad, including the four next to a corner."""
    quad = Object(shape="quad", material="m", segments=1,
                  vertices=[[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]])
    m = Material(ka=0.1, kd=0.7, ks=0.0)
    light = Light(position=(1.0, 1.0, 1.0), attenuation="inverse_square", Ip=(2.0, 2.0, 2.0))
    # eye 4 units away with a 40 degree field of view: the quad's corners lie inside the image;
    # the quad faces the eye, so perspective-correct interpolation is linear in screen space
    scene = _single(quad, m, [light], eye=(0.0, 0.0, 4.0))
    w = 101
    image = render_image(scene, (w, w), "gouraud")
    origins, dirs = primary_rays(scene.camera, w, w)
    t = -origins[..., 2] / dirs[..., 2]
    points = (origins + t[..., None] * dirs)[..., :2]
    mesh = scene_meshes(scene)[0]
    vertex_colors = shade(mesh.vertices, np.array([0, 0, 1.0]), scene.camera.eye, m, [light],
                          (0, 0, 0))
    expected = np.full(image.shape, np.nan)
    for face in mesh.faces:
        a, b, c = mesh.vertices[face, :2]
        basis = np.linalg.inv(np.column_stack([b - a, c - a]))
        uv = (points - a) @ basis.T
        bary = np.stack([1 - uv[..., 0] - uv[..., 1], uv[..., 0], uv[..., 1]], axis=-1)
        inside = np.all(bary > 1e-3, axis=-1)  # off the edges (rasterization ties)
        expected[inside] = bary[inside] @ vertex_colors[face]
    covered = ~np.isnan(expected[..., 0])
    assert covered.sum() > 0.8 * (w * 2 / (2 * 4 * np.tan(np.radians(20)))) ** 2
    np.testing.assert_allclose(image[covered], expected[covered], rtol=2e-3, atol=1e-5)
    corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1.0]])
    checked = 0
    for corner in corners:  # the pixel nearest each corner is on the quad and was compared
        d = np.linalg.norm(points - corner, axis=-1)
        d[~covered] = np.inf
        assert d.min() < 0.08, f"no compared pixel centre near corner {corner}"
        checked += 1
    assert checked == 4
