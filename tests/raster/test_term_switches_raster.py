"""The GL frame with a term of the equation switched off equals the numpy reference raster with
that term off (issue 22: a click on the caption's term), through the renderer's real passes:
premultiplied programs, shadow volumes (S_i off: the stencil passes skipped)."""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.pipelines.reference import iter_reference_raster
from shadelab.raster.offscreen import render_image
from shadelab.scene.preset import load_preset
from shadelab.shading.codes import terms_mask

pytestmark = pytest.mark.gl
SIZE = (64, 48)


def _reference(scene, off=()):
    return list(iter_reference_raster(scene, SIZE, rows_per_chunk=48, off=off))[-1].image


@pytest.mark.parametrize("off", [("ambient",), ("diffuse",), ("specular",), ("attenuation",),
                                 ("ambient", "specular")])
@pytest.mark.parametrize("specular", ["phong", "blinn"])
def test_the_frame_with_a_term_off_matches_the_reference(gl_ctx, off, specular):
    scene = load_preset("lecture", ["render.shadows=none", f"render.specular={specular}",
                                    "lights.0.c2=0.3", "lights.0.c3=0.1"])
    gpu = render_image(scene, SIZE, "phong", specular, terms_mask(off))
    ref = _reference(scene, off)
    whole = render_image(scene, SIZE, "phong", specular)
    scale = float(whole.max())
    assert np.abs(gpu - ref).max() < 1e-3 * scale
    assert np.abs(whole - gpu).max() > 0.02 * scale       # the switch did change the frame
    back = render_image(scene, SIZE, "phong", specular)    # and the next frame is whole again
    np.testing.assert_array_equal(back, whole)


def test_shadow_off_skips_the_volumes_and_matches_the_unshadowed_reference(gl_ctx):
    scene = load_preset("lecture")      # shadows = "volumes"
    assert scene.render.shadows == "volumes"
    ref = _reference(scene)             # the reference raster has no S_i
    shadowed = render_image(scene, SIZE, "phong")
    lit = render_image(scene, SIZE, "phong", None, terms_mask(["shadow"]))
    scale = float(shadowed.max())
    assert np.abs(lit - ref).max() < 1e-3 * scale
    dark = (ref - shadowed).max(axis=-1) > 0.05 * scale     # the shadows S_i = 0 drew
    assert dark.sum() > 20
