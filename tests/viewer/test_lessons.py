"""Lesson files: the shipped lesson loads and covers the lecture's slides in order, a broken
lesson is one line naming the step and the key, and a step sets exactly its view toggles."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from shadelab.errors import ShadeLabError
from shadelab.lab.lesson import SHOW_TOGGLES, LessonRun, go_to, list_lessons, load_lesson
from shadelab.lab.state import AppState
from shadelab.scene import load_preset


def _bare_env() -> dict:
    """No display, a plain PATH; the inherited PYTHONPATH is kept (the code under test)."""
    env = {"PATH": "/usr/bin:/bin", "DISPLAY": ""}
    if "PYTHONPATH" in os.environ:
        env["PYTHONPATH"] = os.environ["PYTHONPATH"]
    return env


GOOD_STEP = '[[steps]]\ntitle = "Ambient"\ncaption = "I = Ia ka"\npreset = "lecture"\n'


def test_every_shipped_lesson_loads_with_every_step_checked():
    assert "phong-to-radiosity" in list_lessons()
    for name in list_lessons():
        lesson = load_lesson(name)            # check=True: each step's preset + overrides load
        assert lesson.steps


def test_the_lecture_lesson_walks_the_slides_in_order():
    captions = [s.caption for s in load_lesson("phong-to-radiosity").steps]
    order = ["Nv = sum_i Ni", "I = Ia ka", "(N . L)", "f_att", "(R . V)^n", "(N . H)^n",
             "sum_i f_att,i", "Gouraud", "S_i", "(1 - kt)", "Ir", "rho(x, x', x'')",
             "B_i = E_i"]
    where = [next(i for i, c in enumerate(captions) if key in c) for key in order]
    assert where == sorted(where), list(zip(order, where, strict=True))


@pytest.mark.parametrize("body, message", [
    ("", "at least one [[steps]]"),
    (GOOD_STEP + "colour = 1\n", "unknown key 'colour'"),
    (GOOD_STEP + 'show = ["compare", "xray"]\n', "show: unknown 'xray'"),
    (GOOD_STEP + 'show = "compare"\n', "'show' must be a list"),
    (GOOD_STEP.replace('"lecture"', '"no-such-preset"'), "no-such-preset"),
    (GOOD_STEP + 'set = ["materials.plastic.kd=7"]\n', "kd"),
])
def test_a_broken_lesson_is_one_line_naming_what_is_wrong(tmp_path, body, message):
    path = tmp_path / "broken.toml"
    path.write_text('name = "x"\n' + body)
    with pytest.raises(ShadeLabError) as info:
        load_lesson(str(path))
    text = str(info.value)
    assert message in text and "\n" not in text


def test_a_broken_lesson_on_the_command_line_exits_2_with_one_line(tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text('name = "x"\n' + GOOD_STEP + 'show = ["xray"]\n')
    run = subprocess.run([sys.executable, "-m", "shadelab", "view", "--lesson", str(path),
                          "--frames", "1"], capture_output=True, text=True, timeout=120,
                         env=_bare_env())
    assert run.returncode == 2
    assert len(run.stderr.strip().splitlines()) == 1 and "xray" in run.stderr


def test_a_step_switches_on_its_view_toggles_and_off_the_rest(tmp_path):
    path = tmp_path / "views.toml"
    path.write_text('name = "v"\n' + GOOD_STEP + 'show = ["compare", "normals"]\n'
                    + GOOD_STEP.replace("Ambient", "Plain"))
    state = AppState.from_scene(load_preset("lecture"), "lecture")
    state.view.show_wireframe = True
    state.walk.lesson = LessonRun(load_lesson(str(path)))
    assert go_to(state, 0)
    on = {name for name, attr in SHOW_TOGGLES.items() if getattr(state.view, attr)}
    assert on == {"compare", "normals"}
    assert go_to(state, 1)
    assert not any(getattr(state.view, attr) for attr in SHOW_TOGGLES.values())
    assert Path(state.walk.lesson.step.preset).stem == "lecture"


def _edited_state() -> AppState:
    state = AppState.from_scene(load_preset("lecture"), "lecture")
    state.scene.materials["plastic"].kd = 0.123
    state.mark_edited()
    state.commit_edit()
    assert state.dirty
    return state


def test_opening_or_dropping_a_lesson_file_starts_it(tmp_path):
    from shadelab.ui import dialogs

    path = tmp_path / "mine.toml"
    path.write_text('name = "mine"\n' + GOOD_STEP + GOOD_STEP.replace('"lecture"', '"cornell"'))
    state = AppState.from_scene(load_preset("sphere-shading"), "sphere-shading")
    dialogs.on_drop([str(path)])
    dialogs.take_dropped(state)
    assert state.error == "" and state.walk.lesson is not None
    assert state.walk.lesson.step is None            # the viewer shows step 1 at the frame's end
    assert go_to(state, 0) and state.scene.name == "lecture"


def test_a_file_that_cannot_open_is_said_at_once_without_asking_about_the_edits(tmp_path):
    state = _edited_state()
    broken = tmp_path / "broken.toml"
    broken.write_text("schema_version = 1\nIa = [nan, 0, 0]\n")
    for path in (str(broken), str(tmp_path / "missing.toml")):
        state.error = ""
        state.request_open(path)
        assert state.pending_open == "" and state.error and "\n" not in state.error
        assert state.scene.materials["plastic"].kd == pytest.approx(0.123)   # edits kept
    state.request_open("cornell")                 # a preset that opens: asks first
    assert state.pending_open == "cornell" and state.scene.name == "lecture"


@pytest.mark.parametrize("argv, message", [
    (["--lesson", "phong-to-radiosity", "--step", "99"], "--step 99: expected 1 to"),
    (["--lesson", "phong-to-radiosity", "--step", "0"], "--step 0: expected 1 to"),
    (["--step", "3"], "--step 3: only with --lesson"),
])
def test_a_bad_lesson_step_exits_2_with_one_line(argv, message):
    run = subprocess.run([sys.executable, "-m", "shadelab", "view", *argv, "--frames", "1"],
                         capture_output=True, text=True, timeout=120,
                         env=_bare_env())
    assert run.returncode == 2
    assert len(run.stderr.strip().splitlines()) == 1 and message in run.stderr
