"""MSAA render targets: a multisample scene pass resolved with a blit smooths polygon edges
and leaves the pixels away from edges exactly as one sample draws them."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from shadelab.scene import load_preset

SIZE = (160, 120)


def _ambient_only():
    """cornell lit by ambient alone: every surface one constant color, so a 1-sample image is
    piecewise constant and each pixel on a polygon edge takes one side's value."""
    scene = load_preset("cornell")
    scene.lights = []
    scene.Ia = (1.0, 1.0, 1.0)
    scene.materials = {name: dataclasses.replace(m, ka=1.0)
                       for name, m in scene.materials.items()}
    return scene


def _neighborhood_range(image: np.ndarray) -> np.ndarray:
    """Per pixel, the largest channel difference to any of its 8 neighbours (edges: inf)."""
    padded = np.pad(image, ((1, 1), (1, 1), (0, 0)), mode="edge")
    h, w = image.shape[:2]
    spread = np.zeros((h, w))
    for dy in (0, 1, 2):
        for dx in (0, 1, 2):
            shifted = padded[dy:dy + h, dx:dx + w]
            spread = np.maximum(spread, np.abs(shifted - image).max(axis=2))
    return spread


@pytest.mark.gl
def test_msaa4_smooths_edges_and_keeps_interior_pixels(gl_ctx):
    from shadelab.gl.target import max_msaa_samples
    from shadelab.ui.viewport import Viewport

    if max_msaa_samples(gl_ctx) < 4:
        pytest.skip("this GL allows fewer than 4 samples (the viewer falls back to 2x2 SSAA)")
    scene = _ambient_only()
    vp = Viewport(gl_ctx)
    try:
        one = vp.draw_scene("one", scene, SIZE, "flat", "phong", samples=1)
        four = vp.draw_scene("four", scene, SIZE, "flat", "phong", samples=4)
        assert (one.target.samples, four.target.samples) == (1, 4)
        a, b = one.target.read(), four.target.read()
    finally:
        vp.release()
    colors = np.unique(a.reshape(-1, 3).round(5), axis=0)
    assert len(colors) <= len(scene.materials) + 1  # the surfaces' colors and background
    # Away from edges (the 1-sample 3x3 neighbourhood is one color) nothing changes.
    interior = _neighborhood_range(a) < 1e-6
    assert interior.mean() > 0.5
    np.testing.assert_allclose(b[interior], a[interior], atol=1e-5, rtol=0)
    # On edges, 1 sample is binary (one side's color); 4 samples give values in between.
    def is_one_of_the_colors(img):
        d = np.abs(img[:, :, None, :] - colors[None, None, :, :]).max(axis=3)
        return d.min(axis=2) < 1e-4
    assert is_one_of_the_colors(a).all()
    blended = ~is_one_of_the_colors(b) & ~interior
    assert blended.sum() > 100, blended.sum()
    assert not (~is_one_of_the_colors(b) & interior).any()
    # ... each a mix of the neighbourhood's colors: inside the range its neighbours span.
    lo = np.minimum.reduce([np.roll(a, (dy, dx), axis=(0, 1)) for dy in (-1, 0, 1)
                            for dx in (-1, 0, 1)])
    hi = np.maximum.reduce([np.roll(a, (dy, dx), axis=(0, 1)) for dy in (-1, 0, 1)
                            for dx in (-1, 0, 1)])
    assert np.all(b[blended] >= lo[blended] - 1e-4) and np.all(b[blended] <= hi[blended] + 1e-4)


@pytest.mark.gl
def test_samples_past_the_gl_limit_are_clamped_and_the_stencil_pass_still_runs(gl_ctx):
    """A multisample target has a stencil per sample: the shadow-volume preset renders."""
    from shadelab.gl.target import RenderTarget, max_msaa_samples
    from shadelab.ui.viewport import Viewport

    limit = max_msaa_samples(gl_ctx)
    target = RenderTarget(gl_ctx, (16, 16), samples=64)
    assert target.samples == limit
    target.release()
    scene = load_preset("shadows")
    vp = Viewport(gl_ctx)
    try:
        one = vp.draw_scene("one", scene, SIZE, "phong", "blinn", samples=1).target.read()
        many = vp.draw_scene("many", scene, SIZE, "phong", "blinn", samples=limit).target.read()
        scene.render.shadows = "none"
        unshadowed = vp.draw_scene("many", scene, SIZE, "phong", "blinn",
                                   samples=limit).target.read()
    finally:
        vp.release()
    # Same image but for edge pixels: shadows (stencil) are where one sample puts them.
    close = np.abs(many - one).max(axis=2) < 1e-4
    assert close.mean() > 0.9
    assert (np.abs(unshadowed - many).max(axis=2) > 1e-3).mean() > 0.02  # shadows were drawn
