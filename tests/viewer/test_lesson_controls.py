"""A lesson step's ``controls`` (issue 22): dotted paths resolved in the step's scene when the
lesson loads (a bad one is one line naming the step), the shipped lesson names 2-4 per step it
owns, and a control writes through the scene model's validation."""

from __future__ import annotations

import pytest

from shadelab.errors import ShadeLabError
from shadelab.lab.controls import check_controls, control_label, resolve, set_value
from shadelab.lab.lesson import LessonRun, go_to, load_lesson
from shadelab.lab.state import AppState
from shadelab.scene import load_preset
from shadelab.scene.model import Light, Material, RenderSettings

STEP = ('[[steps]]\ntitle = "Specular"\ncaption = "ks (R . V)^n"\npreset = "lecture"\n'
        'controls = {controls}\n')


def test_every_shipped_step_names_two_to_four_controls_that_resolve():
    lesson = load_lesson("phong-to-radiosity")
    owned = [s for s in lesson.steps if s.title not in ("Radiosity",)
             and not s.title.startswith("Normals")]   # steps other engineers own
    assert len(owned) == len(lesson.steps) - 2
    for step in owned:
        assert 2 <= len(step.controls) <= 4, step.title
        scene = load_preset(step.preset, step.set)
        assert len(check_controls(scene, step.controls)) == len(step.controls)


def test_a_path_resolves_to_its_field_and_widget():
    scene = load_preset("lecture")
    n = resolve(scene, "materials.plastic.n")
    assert n.owner is scene.materials["plastic"] and n.field == "n" and n.widget == "slider"
    assert n.cls is Material and n.value() == scene.materials["plastic"].n
    spec = resolve(scene, "render.specular")
    assert spec.cls is RenderSettings and spec.widget == "combo"
    assert spec.args == (("phong", "blinn"),)
    c2 = resolve(scene, "lights.0.c2")
    assert c2.cls is Light and c2.owner is scene.lights[0] and c2.args[0] == 0.0
    assert c2.label == "key c2" and n.label == "plastic n"     # the light by its name
    assert resolve(scene, "render.show_volumes").widget == "checkbox"
    assert resolve(scene, "Ia").widget == "color"
    assert [control_label(p) for p in ("materials.plastic.n", "lights.0.c2", "render.specular",
                                       "render.show_volumes")] \
        == ["plastic n", "light 0 c2", "specular", "show volumes"]


@pytest.mark.parametrize("controls, message", [
    ('["materials.plastc.n"]', "control 'materials.plastc.n': no 'plastc'"),
    ('["lights.3.c2"]', "expected an index below 1"),
    ('["render.specularity"]', "no field 'specularity'"),
    ('["objects.0.name"]', "a 'str' field has no control"),
    ('["camera.eye"]', "a 'vec3' field has no control"),
    ('["render.specular", "Ia", "lights.0.c1", "lights.0.c2", "lights.0.c3"]', "at most 4"),
])
def test_a_bad_control_is_one_line_naming_the_step(tmp_path, controls, message):
    path = tmp_path / "bad.toml"
    path.write_text('name = "x"\n' + STEP.format(controls=controls))
    with pytest.raises(ShadeLabError) as info:
        load_lesson(str(path))
    text = str(info.value)
    assert "bad.toml: steps[0] ('Specular')" in text and message in text and "\n" not in text


def test_controls_must_be_a_list_of_strings(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('name = "x"\n' + STEP.format(controls='"materials.plastic.n"'))
    with pytest.raises(ShadeLabError, match=r"steps\[0\]: 'controls' must be a list"):
        load_lesson(str(path))


def test_a_control_writes_through_validation():
    scene = load_preset("lecture")
    n = resolve(scene, "materials.plastic.n")
    version = scene.version
    assert set_value(n, 55.0) and scene.materials["plastic"].n == 55.0
    assert scene.version > version
    assert not set_value(n, 55.0)                       # the same value: no change
    with pytest.raises(ShadeLabError):
        set_value(n, -1.0)                              # the spec's range holds
    assert scene.materials["plastic"].n == 55.0


def test_a_step_starts_with_every_term_on():
    state = AppState.from_scene(load_preset("lecture"), "lecture")
    state.walk.lesson = LessonRun(load_lesson("phong-to-radiosity"))
    go_to(state, 5)
    state.view.terms_off = frozenset({"specular"})
    go_to(state, 6)
    assert state.view.terms_off == frozenset()
