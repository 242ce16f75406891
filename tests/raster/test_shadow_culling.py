"""Flat casters whose volume holds no receiver are skipped (issue 13.5: shadow-volume fill).

``shadows_nothing`` against closed cases, and the frames: skipping the floor under a lecture
scene and the walls of a Cornell box changes no pixel."""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.geometry.silhouette import light_homogeneous, shadows_nothing
from shadelab.scene import load_preset

FLOOR = np.array([[-5, 0, -5], [5, 0, -5], [5, 0, 5], [-5, 0, 5]], float)
UP = np.tile([0.0, 1.0, 0.0], (2, 1))
ABOVE = np.array([[-1.0, 0.0, -1.0], [1.0, 2.0, 1.0]])     # a box standing on the floor
BELOW = np.array([[-1.0, -2.0, -1.0], [1.0, -0.5, 1.0]])


def test_a_floor_lit_from_above_shadows_nothing_above_it():
    light = light_homogeneous("point", (0.0, 4.0, 0.0), None)
    assert shadows_nothing(FLOOR, UP, light, [ABOVE], 1e-6)
    assert not shadows_nothing(FLOOR, UP, light, [ABOVE, BELOW], 1e-6)   # a receiver below
    below = light_homogeneous("point", (0.0, -4.0, 0.0), None)
    assert not shadows_nothing(FLOOR, UP, below, [ABOVE], 1e-6)          # lit from beneath
    sun = light_homogeneous("directional", None, (0.3, -1.0, 0.1))
    assert shadows_nothing(FLOOR, UP, sun, [ABOVE], 1e-6)
    grazing = light_homogeneous("point", (9.0, 0.0, 0.0), None)
    assert not shadows_nothing(FLOOR, UP, grazing, [ABOVE], 1e-6)        # in the plane: kept


def test_only_flat_casters_are_skipped():
    bent = FLOOR.copy()
    bent[2, 1] = 0.5
    light = light_homogeneous("point", (0.0, 4.0, 0.0), None)
    assert not shadows_nothing(bent, UP, light, [ABOVE], 1e-6)
    tilted = np.array([[0.0, 1.0, 0.0], [0.0, 0.9, 0.436]])
    assert not shadows_nothing(FLOOR, tilted, light, [ABOVE], 1e-6)


@pytest.mark.gl
@pytest.mark.parametrize("preset", ["lecture", "shadows", "shadows-colored", "cornell",
                                    "cornell-spheres", "transparency"])
def test_skipping_changes_no_pixel(gl_ctx, monkeypatch, preset):
    from shadelab.raster import shadows
    from shadelab.raster.offscreen import render_image, shared_renderer

    scene = load_preset(preset, ["render.shadows=volumes"])
    size = (96, 72)
    culled = render_image(scene, size)
    renderer = shared_renderer()
    lights = scene.active_lights()
    meshes = renderer.sync(scene)
    def triangles():   # open casters that touch share a volume: count its triangles
        return sum(len(v.volume.faces) for i, light in enumerate(lights)
                   for v in renderer.shadow_volumes.volumes(scene, meshes, i, light))

    kept = triangles()
    monkeypatch.setattr(shadows, "shadows_nothing", lambda *a: False)
    renderer.shadow_volumes.release_volumes()      # its answers are memoized
    every = triangles()
    full = render_image(scene, size)
    renderer.shadow_volumes.release_volumes()      # no answer of the patched function kept
    np.testing.assert_array_equal(culled, full)
    if preset in ("lecture", "shadows", "cornell"):
        assert kept < every                 # the floor / the room's walls were skipped
