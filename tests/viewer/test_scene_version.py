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


def _repr_job_key(state, name, size):
    """The offline job key as ui/pipelines.py built it before issue 21 (repr of the scene)."""
    scene = state.scene
    if name == "radiosity":
        return (name, repr(scene.objects), repr(scene.materials), repr(scene.radiosity),
                scene.base_dir)
    return (name, repr(scene), size, scene.raytrace.spp)


def _orbit(state):
    from shadelab.lab import camera_control

    camera_control.orbit(state.scene.camera, 40.0, -15.0, 480)
    state.mark_edited()


def _zoom(state):
    from shadelab.lab import camera_control

    camera_control.zoom(state.scene.camera, 2.0)
    state.mark_edited()


EDITS = {
    "orbit": _orbit,
    "zoom": _zoom,
    "fov": lambda st: setattr(st.scene.camera, "fov_y", 31.0),
    "kd": lambda st: setattr(st.scene.materials["white"], "kd", 0.5),
    "Od": lambda st: setattr(st.scene.materials["white"], "Od", (0.2, 0.9, 0.3)),
    "translate": lambda st: setattr(st.scene.objects[0], "translate", (0.1, 0.2, 0.3)),
    "object removed": lambda st: st.scene.objects.pop(),
    "patches": lambda st: setattr(st.scene.radiosity, "patches", 123),
    "solver setting": lambda st: setattr(st.scene.radiosity, "iterations", 17),
    "light": lambda st: setattr(st.scene.lights[0], "Ip", (0.3, 0.2, 0.1)),
    "shading": lambda st: setattr(st.scene.render, "shading", "flat"),
    "spp": lambda st: setattr(st.scene.raytrace, "spp", 3),
    "announced, nothing changed": lambda st: st.mark_edited(),
}


@pytest.mark.parametrize("edit", sorted(EDITS))
def test_the_radiosity_job_key_changes_exactly_when_its_repr_key_did(edit):
    """Issue 21: the offline keys use the edit counters, not repr(scene); the radiosity key stays
    view-independent (a camera move, a size or a render setting keep it)."""
    from shadelab.ui.pipelines import job_key

    state = AppState.from_scene(_scene(), "cornell")
    new, old = job_key(state, "radiosity", (64, 48)), _repr_job_key(state, "radiosity", (64, 48))
    assert job_key(state, "radiosity", (128, 96)) == new  # no size in it
    EDITS[edit](state)
    assert (job_key(state, "radiosity", (64, 48)) != new) == \
        (_repr_job_key(state, "radiosity", (64, 48)) != old), edit
    if edit in ("orbit", "zoom", "fov", "light", "shading", "spp"):
        assert job_key(state, "radiosity", (64, 48)) == new, edit


@pytest.mark.parametrize("edit", sorted(EDITS))
def test_the_traced_job_key_moves_on_every_edit_and_with_the_size(edit):
    from shadelab.ui.pipelines import job_key

    state = AppState.from_scene(_scene(), "cornell")
    for name in ("raytrace", "pathtrace"):
        assert job_key(state, name, (64, 48)) == job_key(state, name, (64, 48))
        assert job_key(state, name, (64, 48)) != job_key(state, name, (128, 96))
    before = {name: job_key(state, name, (64, 48)) for name in ("raytrace", "pathtrace")}
    old = _repr_job_key(state, "raytrace", (64, 48))
    EDITS[edit](state)
    for name in ("raytrace", "pathtrace"):
        if _repr_job_key(state, "raytrace", (64, 48)) != old:  # a change the repr saw
            assert job_key(state, name, (64, 48)) != before[name], (edit, name)


def test_a_replaced_scene_changes_the_traced_key_but_an_equal_copy_keeps_radiosity():
    from shadelab.ui.pipelines import job_key

    state = AppState.from_scene(_scene(), "cornell")
    traced, radiosity = job_key(state, "raytrace", (64, 48)), job_key(state, "radiosity", (8, 8))
    state.replace_scene(clone_scene(state.scene))  # undo / redo: a snapshot copy
    assert job_key(state, "raytrace", (64, 48)) != traced
    assert job_key(state, "radiosity", (8, 8)) == radiosity  # same objects, same solution


def test_edit_key_names_its_parts():
    scene = _scene()
    assert scene.edit_key("objects") != scene.edit_key("materials")
    assert scene.edit_key() == ()
    with pytest.raises(ValueError, match="unknown part 'mesh'"):
        scene.edit_key("mesh")
