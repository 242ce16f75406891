"""Transparency against the lecture's formulas on a known stack of quads (GL, small images)."""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.raster.transparency import blend_reference
from shadelab.scene.model import Camera, Material, Object, Scene

pytestmark = pytest.mark.gl

SIZE = (96, 72)
BACKGROUND = (0.2, 0.3, 0.4)


def _quad(z: float, half_w: float, half_h: float, material: str, dx: float = 0.0) -> Object:
    return Object(shape="quad", material=material, normals="flat",
                  vertices=[[dx - half_w, -half_h, z], [dx + half_w, -half_h, z],
                            [dx + half_w, half_h, z], [dx - half_w, half_h, z]])


def stack_scene(opaque_back: bool) -> Scene:
    """Three transparent quads (listed near to far, so only sorting gets them right) over the
    background or an opaque quad; no lights and Ia = ka = 1, so each surface's I1 = Od."""
    materials = {
        "near": Material(ka=1.0, kd=0.0, Od=(0.9, 0.1, 0.1), kt=0.3, transparency="interpolated"),
        "mid": Material(ka=1.0, kd=0.0, Od=(0.1, 0.5, 0.1), kt=0.6, Ot=(1.0, 0.5, 0.25),
                        transparency="filtered"),
        "far": Material(ka=1.0, kd=0.0, Od=(0.1, 0.2, 0.7), kt=0.5, transparency="interpolated"),
        "wall": Material(ka=1.0, kd=0.0, Od=(0.6, 0.6, 0.2)),
    }
    objects = [_quad(0.0, 0.5, 0.5, "near"), _quad(-1.0, 1.0, 1.0, "mid", 0.3),
               _quad(-2.0, 1.5, 1.5, "far")]
    if opaque_back:
        objects.append(_quad(-3.0, 20.0, 20.0, "wall"))
    scene = Scene(Ia=(1.0, 1.0, 1.0), camera=Camera(eye=(0.0, 0.0, 4.0), target=(0, 0, 0),
                                                    fov_y=60.0),
                  materials=materials, objects=objects)
    scene.render.shading = "flat"
    scene.render.background = BACKGROUND
    return scene


def expected(scene: Scene, layers: list[str], behind) -> np.ndarray:
    color = np.asarray(behind, dtype=np.float64)
    for name in layers:  # far to near
        m = scene.materials[name]
        color = blend_reference(m.transparency, m.kt, m.Ot, np.asarray(m.Od), color)
    return color


@pytest.mark.parametrize("shading", ["flat", "gouraud", "phong"])
@pytest.mark.parametrize("opaque_back", [False, True])
def test_stack_of_quads_matches_the_formulas(gl_ctx, shading, opaque_back):
    from shadelab.raster.offscreen import render_image

    scene = stack_scene(opaque_back)
    image = render_image(scene, SIZE, shading)
    behind = scene.materials["wall"].Od if opaque_back else BACKGROUND
    w, h = SIZE
    cx, cy = w // 2, h // 2
    probes = {  # pixel: layers covering it, far to near
        (cy, cx): ["far", "mid", "near"],
        (cy, cx + 13): ["far", "mid"],
        (cy, cx - 13): ["far"],
    }
    for (row, col), layers in probes.items():
        want = expected(scene, layers, behind)
        got = image[row, col]
        assert np.abs(got - want).max() < 1e-5, f"{layers} at {(row, col)}: {got} vs {want}"
    assert np.abs(image[1, 1] - (np.asarray(behind) if opaque_back else BACKGROUND)).max() < 1e-6


def test_order_of_objects_does_not_matter(gl_ctx):
    from shadelab.raster.offscreen import render_image

    scene = stack_scene(True)
    first = render_image(scene, SIZE)
    scene.objects.reverse()
    assert np.abs(render_image(scene, SIZE) - first).max() < 1e-6


def test_formulas():
    I1, I2 = np.array([0.5, 0.2, 0.1]), np.array([0.4, 0.8, 1.0])
    assert np.allclose(blend_reference("interpolated", 0.25, (1, 1, 1), I1, I2),
                       0.75 * I1 + 0.25 * I2)
    assert np.allclose(blend_reference("filtered", 0.5, (1.0, 0.5, 0.0), I1, I2),
                       I1 + np.array([0.2, 0.2, 0.0]))


def test_preset_renders_all_models(gl_ctx):
    from shadelab.raster.offscreen import render_image
    from shadelab.scene import load_preset

    scene = load_preset("transparency")
    models = {m.transparency for m in scene.materials.values() if m.kt > 0}
    assert models == {"interpolated", "filtered"}
    image = render_image(scene, (80, 60))
    opaque = load_preset("transparency")
    for m in opaque.materials.values():
        m.kt = 0.0
    assert np.isfinite(image).all()
    assert np.abs(render_image(opaque, (80, 60)) - image).max() > 0.05
