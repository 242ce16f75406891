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
