"""Colour pickers show colours as they appear on screen (issue 20, item 4).

Presets and the lecture's arithmetic hold linear RGB; the viewer's colour widget
(``shadelab.ui.panels.rgb_color``) shows linear_to_srgb(value) and stores
srgb_to_linear(edited). The check, without a GUI: a fully lit kd = 1 surface of colour Od
under a white directional light (Ip = 1, Ia = 0) is drawn with the pixel the picker shows
for Od, within 1 level of 255.
"""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.scene.model import Camera, Light, Material, Object, RenderSettings, Scene
from shadelab.shading.conventions import linear_to_srgb, srgb_to_linear
from shadelab.testing import as_srgb8
from shadelab.ui.panels import shown_color, stored_color

COLORS = [(0.2, 0.5, 0.8), (0.8, 0.1, 0.02), (0.0021, 0.04, 1.0), (0.5, 0.5, 0.5)]


def _lit_quad(od) -> Scene:
    quad = Object(shape="quad", material="m", normals="flat",
                  vertices=[[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [1.0, 1.0, 0.0],
                            [-1.0, 1.0, 0.0]])
    return Scene(Ia=(0.0, 0.0, 0.0),
                 camera=Camera(eye=(0.0, 0.0, 3.0), target=(0.0, 0.0, 0.0), fov_y=30.0),
                 lights=[Light(kind="directional", direction=(0.0, 0.0, -1.0), Ip=(1.0, 1.0, 1.0))],
                 materials={"m": Material(ka=0.0, kd=1.0, ks=0.0, Od=tuple(od))},
                 objects=[quad], render=RenderSettings(shadows="none", shading="flat"))


@pytest.mark.gl
@pytest.mark.parametrize("od", COLORS)
def test_picker_shows_the_pixel_a_fully_lit_white_surface_of_that_colour_gets(gl_ctx, od):
    from shadelab.api import render

    image = render(_lit_quad(od), size=(16, 16))
    pixel = as_srgb8(image)[8, 8].astype(int)
    shown = np.round(np.asarray(shown_color(od)) * 255.0).astype(int)
    assert np.abs(shown - pixel).max() <= 1, (shown, pixel)
    # the picker does not show the linear value (the 0.5 grey would read 128, the pixel 188)
    assert np.abs(np.round(np.asarray(od) * 255.0) - pixel).max() > 1


def test_picker_stores_the_linear_value_of_the_edited_colour():
    """Closed form: sRGB 0.5 is linear 0.21404; an untouched value round-trips."""
    assert stored_color((0.5, 0.5, 0.5)) == pytest.approx((0.214041,) * 3, abs=1e-6)
    assert shown_color((0.214041, 0.0, 1.0)) == pytest.approx((0.5, 0.0, 1.0), abs=1e-6)
    x = np.linspace(0.0, 1.2, 241)
    np.testing.assert_allclose(srgb_to_linear(linear_to_srgb(x)), x, atol=1e-12)
    assert linear_to_srgb(0.0031308) == pytest.approx(0.0031308 * 12.92)
