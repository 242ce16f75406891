"""Issue 24, item 4: a lesson step's ``pipeline`` and ``focus`` are checked like the rest of
the file: a pipeline of shadelab.pipelines.names(), panels the viewer has, strings where
strings belong; one line naming the step and the key, exit 2, before any window."""

from __future__ import annotations

import pytest

from conftest import checksums
from shadelab import pipelines
from shadelab.lab.lesson_file import list_lessons, load_lesson

STEP = '''title = "Diffuse"
caption = "I = Ip kd (N . L)"
preset = "cornell"
'''


@pytest.mark.parametrize("extra, named", [
    ('pipeline = "raytracer"', "pipeline"),
    ("pipeline = 3", "pipeline"),
    ('pipeline = ["phong"]', "pipeline"),
    ('pipeline = "PHONG"', "pipeline"),
    ('focus = "NoPanel"', "focus"),
    ('focus = "Materials,,Lights"', "focus"),
    ('focus = ["Materials"]', "focus"),
    ("focus = 1", "focus"),
    ('title = ["Diffuse"]', "title"),
    ('caption = 2', "caption"),
    ('preset = ["cornell"]', "preset"),
    ('show = "normals"', "show"),
    ('set = "Ia=[0,0,0]"', "set"),
])
def test_a_bad_step_key_is_one_line_naming_step_and_key(shadelab, tmp_path, extra, named):
    key = extra.split("=", 1)[0].strip()
    body = "\n".join(line for line in STEP.splitlines() if not line.startswith(key + " "))
    lesson = tmp_path / "lesson.toml"
    lesson.write_text('name = "hostile"\n\n[[steps]]\n' + STEP + "\n[[steps]]\n" + body
                      + "\n" + extra + "\n", encoding="utf-8")
    before = checksums([lesson])
    err = shadelab("view", "--lesson", str(lesson), "--no-autosave", timeout=60)
    assert err.count("\n") == 1 and "steps[1]" in err and named in err, err
    assert checksums([lesson]) == before


def test_a_bad_lesson_name_is_one_line(shadelab, tmp_path):
    lesson = tmp_path / "lesson.toml"
    lesson.write_text("name = 5\n\n[[steps]]\n" + STEP, encoding="utf-8")
    err = shadelab("view", "--lesson", str(lesson), "--no-autosave", timeout=60)
    assert "name" in err


@pytest.mark.parametrize("name", list_lessons())
def test_the_shipped_lessons_pass_the_checks(name):
    lesson = load_lesson(name)
    for step in lesson.steps:
        assert not step.pipeline or step.pipeline in pipelines.names()
