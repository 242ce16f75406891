"""Images that say what they are (issue 20, item 8): PNGs carry text chunks (preset,
overrides, pipeline, shading, ShadeLab version, software) and an sRGB chunk; ``-o X.exr`` and
``Image.save("x.exr")`` write linear float32 RGB equal to the ``--npy`` array."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest
from PIL import Image as PILImage

import shadelab
from shadelab.cli import main

OpenEXR = pytest.importorskip("OpenEXR")


def _exr(path) -> tuple[np.ndarray, dict]:
    with OpenEXR.File(str(path)) as f:
        return np.array(f.channels()["RGB"].pixels), dict(f.header())


@pytest.mark.gl
def test_render_png_says_what_made_it(tmp_path, capsys):
    out = tmp_path / "a.png"
    assert main(["render", "lecture", "-o", str(out), "--size", "32x24", "--shading", "gouraud",
                 "--set", "lights.0.Ip=2,2,2", "--set", "Ia=0.2,0.2,0.2"]) == 0
    with PILImage.open(out) as im:
        info = dict(im.info)
    assert info["preset"] == "lecture"
    assert json.loads(info["overrides"]) == ["lights.0.Ip=2,2,2", "Ia=0.2,0.2,0.2"]
    assert info["pipeline"] == "raster" and info["shading"] == "gouraud"
    assert info["ShadeLab version"] == shadelab.__version__
    assert info["Software"] == f"ShadeLab {shadelab.__version__}"
    assert info["srgb"] == 0                                  # perceptual intent
    assert info["gamma"] == pytest.approx(1 / 2.2, abs=1e-5)  # the sRGB chunk's fallback
    out2 = tmp_path / "b.png"
    assert main(["render", "lecture", "-o", str(out2), "--size", "32x24"]) == 0
    with PILImage.open(out2) as im:
        assert im.info["shading"] == shadelab.load_preset("lecture").render.shading
        assert json.loads(im.info["overrides"]) == []


def test_raytrace_exr_equals_the_npy_array(tmp_path, capsys):
    exr, npy = tmp_path / "a.exr", tmp_path / "a.npy"
    assert main(["raytrace", "lecture", "-o", str(exr), "--npy", str(npy), "--size",
                 "20x12", "--set", "render.exposure=2.0"]) == 0
    pixels, header = _exr(exr)
    array = np.load(npy)
    assert pixels.dtype == np.float32 and pixels.shape == (12, 20, 3)
    np.testing.assert_array_equal(pixels, array)      # linear, exposure not applied
    assert header["preset"] == "lecture" and header["pipeline"] == "raytrace"
    assert header["ShadeLab version"] == shadelab.__version__


def test_api_image_saves_exr_and_a_png_with_its_chunks(tmp_path):
    rng = np.random.default_rng(7)
    array = rng.random((5, 7, 3), dtype=np.float32) * 3.0    # HDR values above 1 survive
    image = shadelab.Image(array, exposure=0.5,
                           info={"pipeline": "pathtrace", "preset": "cornell",
                                 "overrides": {"materials.white.kd": 0.8}})
    assert image.save(tmp_path / "x.exr") == tmp_path / "x.exr"
    pixels, header = _exr(tmp_path / "x.exr")
    np.testing.assert_array_equal(pixels, array)
    assert header["pipeline"] == "pathtrace"
    image.save(tmp_path / "x.png")
    with PILImage.open(tmp_path / "x.png") as im:
        info, decoded = dict(im.info), np.asarray(im)
    assert info["pipeline"] == "pathtrace" and info["preset"] == "cornell"
    assert json.loads(info["overrides"]) == ["materials.white.kd=0.8"]
    assert "shading" not in info and info["srgb"] == 0
    np.testing.assert_array_equal(decoded, image.to_srgb8())


def test_exr_bad_outputs_are_one_line(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert main(["raytrace", "lecture", "-o", str(blocker / "a.exr"), "--size", "8x8"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "a.exr" in err and "a folder is expected" in err
    kept = tmp_path / "kept.exr"
    kept.write_bytes(b"keep")
    os.chmod(kept, 0o444)
    with pytest.raises(shadelab.ShadeLabError, match="read-only") as info:
        shadelab.Image(np.zeros((2, 2, 3))).save(kept)
    assert "\n" not in str(info.value) and kept.read_bytes() == b"keep"
    with pytest.raises(shadelab.ShadeLabError, match=r"\.png or \.npy file name, or \.exr"):
        shadelab.Image(np.zeros((2, 2, 3))).save(tmp_path / "x.hdr")
