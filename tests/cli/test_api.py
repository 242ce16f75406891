"""The Python API (shadelab.api): presets, validated edits, every pipeline, probe, Image, show."""

from __future__ import annotations

import io
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image as PILImage

import shadelab
from shadelab.cli import main
from shadelab.errors import ShadeLabError

ROOT = Path(__file__).resolve().parents[2]


def test_import_is_cheap_and_gl_free():
    code = ("import sys, shadelab; shadelab.load_preset; "
            "print(sorted({m.split('.')[0] for m in sys.modules} & "
            "{'numpy', 'moderngl', 'glfw', 'imgui_bundle', 'OpenGL', 'trimesh', 'numba'}))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "['numpy']"  # the API module itself needs only numpy
    bare = subprocess.run([sys.executable, "-c", "import sys, shadelab; "
                           "print('numpy' in sys.modules)"], capture_output=True, text=True)
    assert bare.stdout.strip() == "False"


def test_overrides_dict_and_list_are_the_same_as_set():
    a = shadelab.load_preset("cornell", overrides={"materials.white.kd": 0.5,
                                                   "lights.0.Ip": (2, 2, 2),
                                                   "render.shading": "flat"})
    b = shadelab.load_preset("cornell", overrides=["materials.white.kd=0.5",
                                                   "lights.0.Ip=2,2,2", "render.shading=flat"])
    assert a == b
    assert a.materials["white"].kd == 0.5 and a.lights[0].Ip == (2.0, 2.0, 2.0)
    assert a.render.shading == "flat"


@pytest.mark.parametrize("overrides, message", [
    ({"materials.white.kd": 2}, "key 'materials.white.kd': expected a number in [0, 1]"),
    (["nokey.x=1"], "--set 'nokey': no such key"),
    ({"render.shading": "toon"}, "expected flat | gouraud | phong"),
])
def test_bad_overrides_fail_with_the_cli_message(overrides, message, capsys):
    with pytest.raises(ShadeLabError) as exc:
        shadelab.load_preset("cornell", overrides=overrides)
    assert message in str(exc.value)


def test_assignment_is_validated_and_canonical():
    scene = shadelab.load_preset("cornell")
    white = scene.materials["white"]
    white.kd = 0.25
    assert white.kd == 0.25
    with pytest.raises(ShadeLabError, match=r"Material: key 'kd': expected a number in \[0, 1\]"):
        white.kd = 1.5
    assert white.kd == 0.25  # refused: the old value stays
    with pytest.raises(ShadeLabError, match="expected true or false"):
        scene.lights[0].enabled = "yes"
    with pytest.raises(ShadeLabError, match="gouraud"):
        scene.render.shading = "toon"
    with pytest.raises(ShadeLabError, match="integer"):
        scene.raytrace.depth = 2.5
    scene.camera.eye = [1, 2, 3]
    assert scene.camera.eye == (1.0, 2.0, 3.0)  # stored as the loader stores it


@pytest.mark.gl
def test_raster_render_matches_the_cli(gl_ctx, tmp_path):
    for shading in ("flat", "gouraud", "phong"):
        npy = tmp_path / f"{shading}.npy"
        assert main(["render", "cornell", "-o", str(tmp_path / "x.png"), "--size", "48x32",
                     "--shading", shading, "--npy", str(npy)]) == 0
        image = shadelab.render("cornell", size=(48, 32), shading=shading)
        assert image.array.dtype == np.float32 and image.array.shape == (32, 48, 3)
        np.testing.assert_array_equal(image.array, np.load(npy))
        assert image.info["shading"] == shading


@pytest.mark.gl
@pytest.mark.slow
@pytest.mark.parametrize("pipeline, cli", [
    ("painter", ["render", "--visibility", "painter"]),
    ("raytrace", ["raytrace", "--depth", "2"]),
    ("pathtrace", ["pathtrace", "--spp", "2", "--seed", "3"]),
    ("radiosity", ["radiosity", "--patches", "60"]),
])
def test_offline_pipelines_match_the_cli(gl_ctx, tmp_path, pipeline, cli):
    npy = tmp_path / "cli.npy"
    command, *flags = cli
    assert main([command, "cornell", "-o", str(tmp_path / "x.png"), "--size", "24x16",
                 "--npy", str(npy), *flags]) == 0
    kwargs = {"raytrace": {"depth": 2}, "pathtrace": {"spp": 2, "seed": 3},
              "radiosity": {"patches": 60}}.get(pipeline, {})
    image = shadelab.render("cornell", size=(24, 16), pipeline=pipeline, **kwargs)
    assert image.array.shape == (16, 24, 3) and image.info["pipeline"] == pipeline
    np.testing.assert_allclose(image.array, np.load(npy), rtol=1e-5, atol=1e-6)
    assert image.array.max() > 0.0


@pytest.mark.parametrize("kwargs, message", [
    ({"pipeline": "toon"}, "pipeline 'toon': expected one of raster, painter"),
    ({"shading": "toon"}, "shading 'toon'"),
    ({"shading": "flat", "pipeline": "raytrace"}, "applies to the raster and painter"),
    ({"size": (0, 10)}, "expected each side in [1, 16384]"),
    ({"size": "big"}, "expected WxH"),
    ({"pipeline": "raytrace", "depth": 99}, "--depth 99"),
])
def test_bad_render_arguments(kwargs, message):
    with pytest.raises(ShadeLabError) as exc:
        shadelab.render("cornell", **kwargs)
    assert message in str(exc.value)


def test_probe_returns_the_terms_as_data():
    scene = shadelab.load_preset("cornell")
    terms = shadelab.probe(scene, (40, 100), size=160, shading="phong")
    json.dumps(terms)  # plain data
    assert terms["material"] == "white" and len(terms["lights"]) == len(scene.active_lights())
    total = np.add(terms["ambient"], terms["emission"])
    for light in terms["lights"]:
        total = total + np.add(light["diffuse"], light["specular"])
        assert abs(np.linalg.norm(light["to_light"]) - 1.0) < 1e-9
    np.testing.assert_allclose(terms["total"], total, rtol=1e-12)
    np.testing.assert_allclose(terms["reference"], terms["total"], rtol=1e-12)  # Phong: same
    assert terms["total"][0] > 0.0
    # Lambert by hand: Ip f_att kd Od (N.L) at the probed point
    light, white = scene.lights[0], scene.materials["white"]
    n_dot_l = float(np.dot(terms["normal"], terms["lights"][0]["to_light"]))
    expected = (np.array(light.Ip) * terms["lights"][0]["f_att"] * white.kd
                * np.array(white.Od) * n_dot_l)
    np.testing.assert_allclose(terms["lights"][0]["diffuse"], expected, rtol=1e-9)
    with pytest.raises(ShadeLabError, match="outside the 160x160 image"):
        shadelab.probe(scene, (160, 0), size=160)


@pytest.mark.gl
def test_probe_agrees_with_the_rendered_pixel(gl_ctx):
    scene = shadelab.load_preset("cornell")
    image = shadelab.render(scene, size=160, shading="phong")
    terms = shadelab.probe(scene, (40, 100), size=160, shading="phong")
    np.testing.assert_allclose(image.array[100, 40], terms["reference"], rtol=0.02, atol=2e-3)


def test_image_save_and_repr_png(tmp_path):
    ramp = np.linspace(0.0, 1.0, 4 * 5 * 3, dtype=np.float32).reshape(4, 5, 3)
    image = shadelab.Image(ramp, exposure=0.5)
    png = PILImage.open(io.BytesIO(image._repr_png_()))
    np.testing.assert_array_equal(np.asarray(png), image.to_srgb8())
    assert image.to_srgb8()[-1, -1, -1] == 188  # sRGB(0.5) = 0.7354 -> 188
    image.save(tmp_path / "a.png")
    image.save(tmp_path / "a.npy")
    np.testing.assert_array_equal(np.load(tmp_path / "a.npy"), ramp)  # linear, unscaled
    np.testing.assert_array_equal(np.asarray(PILImage.open(tmp_path / "a.png")), image.to_srgb8())
    with pytest.raises(ShadeLabError, match="expected a .png or .npy"):
        image.save(tmp_path / "a.jpg")
    with pytest.raises(ShadeLabError, match=r"expected an \(H, W, 3\) array"):
        shadelab.Image(np.zeros((4, 4)))


def test_show_without_a_display_is_a_clear_error(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    with pytest.raises(ShadeLabError, match="no display"):
        shadelab.show("cornell")


@pytest.mark.gl
@pytest.mark.slow
def test_example_script_runs_headless(gl_ctx, tmp_path):
    out = subprocess.run([sys.executable, str(ROOT / "examples" / "quickstart.py"),
                          str(tmp_path / "out")], cwd=tmp_path, capture_output=True, text=True,
                         timeout=300)
    assert out.returncode == 0, out.stderr
    assert "refused: Material: key 'kd'" in out.stdout
    for name in ("flat", "gouraud", "phong", "raytrace"):
        assert (tmp_path / "out" / f"cornell_{name}.png").stat().st_size > 1000


def test_render_is_a_plain_function_with_its_real_signature_and_docstring():
    import inspect

    import shadelab.raster  # the raster subpackage no longer shadows the function

    assert inspect.isfunction(shadelab.render)
    params = inspect.signature(shadelab.render).parameters
    assert list(params)[:4] == ["scene", "size", "shading", "pipeline"]
    assert shadelab.render.__doc__.startswith("Render a scene")
    assert shadelab.raster.__name__ == "shadelab.raster"
