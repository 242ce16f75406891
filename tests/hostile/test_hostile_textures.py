"""Issue 24, item 5: a texture wider or taller than GL_MAX_TEXTURE_SIZE (a GL_INVALID_VALUE
that drew the material black) is resampled for the raster, with a one-line note."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

PRESET = """schema_version = 1
[materials.m]
kd = 0.8
texture = "wide.png"
[[lights]]
position = [0.0, 5.0, 3.0]
[[objects]]
shape = "sphere"
material = "m"
"""


@pytest.mark.parametrize("shape, limit, expected", [
    ((4, 10, 3), 5, (2, 5, 3)),
    ((10, 4), 5, (5, 2)),
    ((3, 4, 3), 5, (3, 4, 3)),
    ((1, 40, 3), 8, (1, 8, 3)),
])
def test_fit_texture_keeps_the_aspect_and_the_mean(shape, limit, expected):
    from shadelab.raster.textures import fit_texture

    pixels = np.random.default_rng(3).random(shape).astype(np.float32)
    out = fit_texture(pixels, limit)
    assert out.shape == expected and out.dtype == np.float32
    assert abs(float(out.mean()) - float(pixels.mean())) < 0.05


def test_a_texture_past_the_gl_limit_is_drawn_not_black(shadelab, tmp_path):
    from shadelab.gl.context import headless_context

    limit = int(headless_context().info.get("GL_MAX_TEXTURE_SIZE", 4096))
    Image.fromarray(np.full((2, limit + 100, 3), 200, np.uint8)).save(tmp_path / "wide.png")
    (tmp_path / "p.toml").write_text(PRESET)
    err = shadelab("render", "p.toml", "-o", "out.png", "--npy", "out.npy", "--size", "32x24",
                   code=0, timeout=180)
    assert "GL_MAX_TEXTURE_SIZE" in err and len(err.splitlines()) <= 3, err
    image = np.load(tmp_path / "out.npy")
    assert np.median(image[image.sum(axis=2) > 0]) > 0.05  # the sphere is lit, not black


@pytest.mark.parametrize("command", ["render", "raytrace"])
def test_a_png_whose_text_chunk_is_a_decompression_bomb_is_one_line(shadelab, tmp_path,
                                                                     command):
    """A zTXt chunk that inflates past Pillow's MAX_TEXT_CHUNK: Pillow's ValueError reached
    the user as a traceback from both renderers (issue 24, class 4)."""
    from PIL import PngImagePlugin

    info = PngImagePlugin.PngInfo()
    info.add_text("comment", "x" * (PngImagePlugin.MAX_TEXT_CHUNK * 4), zip=True)
    Image.fromarray(np.full((8, 8, 3), 90, np.uint8)).save(tmp_path / "wide.png", pnginfo=info)
    (tmp_path / "p.toml").write_text(PRESET)
    err = shadelab(command, "p.toml", "-o", "out.png", "--size", "16x12", code=2, timeout=180)
    assert "materials.m.texture: 'wide.png' could not be read as an image" in err
    assert "MAX_TEXT_CHUNK" in err and not (tmp_path / "out.png").exists()
