"""Scene.version (shadelab.scene.model): the edit counter the viewer keys its image on. Every
value-changing assignment anywhere in the scene moves it, announced by ``mark_edited`` or not;
reading the scene (or the counter) and writing back the same value do not."""

from __future__ import annotations

import pytest

from shadelab.errors import ShadeLabError
from shadelab.lab.state import AppState
from shadelab.scene import load_preset
from shadelab.scene.model import Light
from shadelab.scene.preset import clone_scene, scene_to_dict


def _scene():
    return load_preset("cornell")


@pytest.mark.parametrize("edit", [
    lambda s: setattr(s.materials["white"], "kd", 0.5),
    lambda s: setattr(s.lights[0], "Ip", (0.3, 0.2, 0.1)),
    lambda s: setattr(s.camera, "fov_y", 31.0),
    lambda s: setattr(s.render, "shading", "flat"),
    lambda s: setattr(s.objects[0], "translate", (0.1, 0.2, 0.3)),
    lambda s: setattr(s, "Ia", (0.2, 0.2, 0.2)),
    lambda s: s.lights.append(Light()),
    lambda s: s.lights.pop(),
    lambda s: s.materials.pop("white"),
    lambda s: s.objects.__setitem__(0, clone_scene(s).objects[1]),
])
def test_an_edit_anywhere_moves_the_version_by_one(edit):
    scene = _scene()
    before = scene.version
    edit(scene)
    assert scene.version == before + 1
    assert scene.version == before + 1  # reading again changes nothing


def test_reading_and_rewriting_the_same_value_keep_the_version():
    scene = _scene()
    before = scene.version
    scene_to_dict(scene), repr(scene), clone_scene(scene), scene.active_lights()
    scene.materials["white"].kd = scene.materials["white"].kd
    scene.lights[0].Ip = list(scene.lights[0].Ip)  # canonical form: the same tuple
    assert scene.version == before


def test_a_rejected_value_keeps_the_version():
    scene = _scene()
    before = scene.version
    with pytest.raises(ShadeLabError):
        scene.materials["white"].kd = 1.5
    assert scene.version == before


def test_the_viewer_sees_an_edit_nobody_announced():
    """The viewport key moves on a nested edit without mark_edited (it compared repr(scene))."""
    from shadelab.ui.app import Viewer, ViewerOptions

    viewer = Viewer(AppState.from_scene(_scene(), "cornell"), ViewerOptions())
    key = viewer.frame_key((64, 48))
    assert viewer.frame_key((64, 48)) == key
    viewer.state.scene.materials["white"].kd = 0.5
    edited = viewer.frame_key((64, 48))
    assert edited != key
    viewer.state.scene.lights[0].Ip = (0.3, 0.2, 0.1)
    assert viewer.frame_key((64, 48)) != edited
