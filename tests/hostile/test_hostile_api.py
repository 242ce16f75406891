"""Issue 24, item 3: every public function of shadelab.api checks its arguments like a preset
is checked: a wrong type or value is a ShadeLabError of one line naming it."""

from __future__ import annotations

import numpy as np
import pytest

from shadelab import api
from shadelab.errors import ShadeLabError


@pytest.fixture(scope="module")
def scene():
    return api.load_preset("cornell")


def _one_line(call, named: str) -> None:
    with pytest.raises(ShadeLabError) as info:
        call()
    text = str(info.value)
    assert "\n" not in text and named in text, text


@pytest.mark.parametrize("kwargs, named", [
    ({"pipeline": "radiosity", "form_factors": "magic"}, "form_factors"),
    ({"pipeline": "radiosity", "form_factors": 3}, "form_factors"),
    ({"pipeline": "radiosity", "solver": "magic"}, "solver"),
    ({"pipeline": "radiosity", "patches": 0}, "patches"),
    ({"pipeline": "radiosity", "patches": 2.5}, "patches"),
    ({"pipeline": "pathtrace", "seed": -1}, "seed"),
    ({"pipeline": "pathtrace", "seed": 1.0}, "seed"),
    ({"pipeline": "pathtrace", "seed": None}, "seed"),
    ({"pipeline": "raytrace", "depth": "3"}, "depth"),
    ({"pipeline": "raytrace", "depth": -1}, "depth"),
    ({"pipeline": "raytrace", "depth": True}, "depth"),
    ({"pipeline": "pathtrace", "spp": 1.5}, "spp"),
    ({"pipeline": "pathtrace", "spp": 0}, "spp"),
    ({"pipeline": "raytrace", "workers": "2"}, "workers"),
    ({"pipeline": "raytrace", "workers": 0}, "workers"),
    ({"pipeline": "raytrace", "backend": "cuda"}, "backend"),
    ({"pipeline": "raytrace", "fresnel": "yes"}, "fresnel"),
    ({"shading": 3}, "shading"),
    ({"shading": "toon"}, "shading"),
    ({"specular": ["phong"]}, "specular"),
    ({"pipeline": 7}, "pipeline"),
    ({"pipeline": "nope"}, "nope"),
    ({"size": (1.5, 2)}, "size"),
    ({"size": "big"}, "big"),
    ({"size": 0}, "size"),
    ({"progress": "no"}, "progress"),
])
def test_render_arguments(scene, kwargs, named):
    kwargs.setdefault("size", (8, 6))
    _one_line(lambda: api.render(scene, **kwargs), named)


@pytest.mark.parametrize("call, named", [
    (lambda s: api.load_preset("cornell", overrides=5), "overrides"),
    (lambda s: api.load_preset("cornell", overrides=[5]), "overrides"),
    (lambda s: api.load_preset("cornell", overrides={1: 2}), "overrides"),
    (lambda s: api.load_preset("cornell", overrides=b"x=1"), "overrides"),
    (lambda s: api.load_preset(5), "name_or_path"),
    (lambda s: api.load_preset(""), "name_or_path"),
    (lambda s: api.save_preset("cornell", "x.toml"), "Scene"),
    (lambda s: api.save_preset(s, 5), "path"),
    (lambda s: api.save_preset(s, ""), "path"),
    (lambda s: api.render(5), "Scene"),
    (lambda s: api.probe(s, (1.5, 2)), "pixel"),
    (lambda s: api.probe(s, "12"), "pixel"),
    (lambda s: api.probe(s, (1, 2), shading=5), "shading"),
    (lambda s: api.probe(s, (1, 2), size=(8.5, 6)), "size"),
    (lambda s: api.show(s, frames="1"), "frames"),
    (lambda s: api.show(s, frames=-1), "frames"),
    (lambda s: api.show(s, frames=1, autosave="no"), "autosave"),
    (lambda s: api.show(s, frames=1, screenshot=5), "screenshot"),
    (lambda s: api.show(s, frames=1, window="huge"), "huge"),
    (lambda s: api.Image(np.zeros((2, 2, 3))).save(""), "path"),
    (lambda s: api.Image(np.zeros((2, 2, 3))).save(None), "path"),
    (lambda s: api.Image(np.zeros((2, 2, 3))).save("x.bmp"), "x.bmp"),
    (lambda s: api.Image("pixels"), "image"),
    (lambda s: api.Image(np.zeros((2, 2))), "image"),
    (lambda s: api.Image(np.zeros((2, 2, 3)), exposure="1"), "exposure"),
    (lambda s: api.Image(np.zeros((2, 2, 3)), exposure=float("nan")), "exposure"),
    (lambda s: api.Image(np.zeros((2, 2, 3)), info=5), "info"),
])
def test_every_public_function_checks_its_arguments(scene, call, named, tmp_path,
                                                    monkeypatch):
    monkeypatch.chdir(tmp_path)
    before = set(tmp_path.iterdir())
    _one_line(lambda: call(scene), named)
    assert set(tmp_path.iterdir()) == before  # nothing written


def _lecture_edited(edit):
    import copy

    import shadelab

    scene = shadelab.load_preset("lecture")
    if edit == "eye on the target":
        scene.camera.eye = scene.camera.target
    elif edit == "17 lights":
        scene.lights.extend(copy.deepcopy(scene.lights[0]) for _ in range(16))
    elif edit == "zero scale":
        scene.objects[1].scale = (0.0, 0.0, 0.0)
    elif edit == "lights None":
        scene.lights = None
    elif edit == "a quad without vertices":
        scene.objects[0].shape, scene.objects[0].vertices = "quad", []
    elif edit == "an unknown material":
        scene.objects[1].material = "nowhere"
    return scene


@pytest.mark.parametrize("edit, words", [
    ("eye on the target", "camera.target': expected a point other than the eye"),
    ("17 lights", "at most 16 lights, got 17"),
    ("zero scale", "objects.1.scale': expected non-zero scales"),
    ("lights None", "key 'lights': expected a list of Light, got NoneType"),
    ("a quad without vertices", "objects.0.vertices': expected 4 points"),
    ("an unknown material", "objects.1.material': expected a material name"),
])
@pytest.mark.parametrize("call", ["render", "probe", "save_preset"])
def test_a_scene_edited_in_python_is_checked_as_a_preset(tmp_path, edit, words, call):
    """Issue 24, class 10: these rendered silently (a near-black image, a light dropped) or
    reached deep errors; the API now refuses what a preset would, in one line."""
    import shadelab

    scene = _lecture_edited(edit)
    with pytest.raises(shadelab.ShadeLabError, match=words) as failure:
        if call == "render":
            shadelab.render(scene, size=16)
        elif call == "probe":
            shadelab.probe(scene, (8, 8), size=16)
        else:
            shadelab.save_preset(scene, tmp_path / "edited.toml")
    assert "\n" not in str(failure.value) and not (tmp_path / "edited.toml").exists()
