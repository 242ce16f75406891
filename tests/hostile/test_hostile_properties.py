"""Property-based hostile input (issue 24, item 7): whatever values a user types into --set,
a lesson step or an exercise task, loading either succeeds or raises ShadeLabError with one
line — never another exception. Files are written and read as users' files are."""

from __future__ import annotations

import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from shadelab.errors import ShadeLabError

VALUES = st.one_of(
    st.none(), st.booleans(), st.integers(-10**12, 10**12),
    st.floats(allow_nan=True, allow_infinity=True), st.text(max_size=12),
    st.lists(st.floats(-1e6, 1e6), max_size=5), st.lists(st.text(max_size=5), max_size=3),
    st.dictionaries(st.text(max_size=4), st.integers(), max_size=2))
KEYS = st.sampled_from([
    "materials.plastic.kd", "materials.plastic.Od", "lights.0.Ip", "lights.0.kind",
    "lights.0.attenuation", "camera.fov_y", "camera.eye", "render.shading", "objects.0.scale",
    "objects.1.material", "Ia", "raytrace.depth", "radiosity.patches", "lights.7.Ip",
    "materials.new.kd", "objects.0.shape"])
SETTINGS = settings(max_examples=60, deadline=None,
                    suppress_health_check=[HealthCheck.function_scoped_fixture])


def _one_line(exc: ShadeLabError) -> None:
    assert str(exc) and "\n" not in str(exc), repr(str(exc))


@SETTINGS
@given(key=KEYS, value=VALUES)
def test_any_set_value_loads_or_is_one_line(key, value):
    from shadelab.api import _override_items
    from shadelab.scene.preset import load_preset

    try:
        items = _override_items({key: value})
        load_preset("lecture", items)
    except ShadeLabError as exc:
        _one_line(exc)


STEP_KEYS = st.sampled_from(["title", "caption", "preset", "pipeline", "focus", "show", "set",
                             "unknown"])


@SETTINGS
@given(steps=st.lists(st.dictionaries(STEP_KEYS, VALUES.filter(lambda v: v is not None),
                                      max_size=4), min_size=0, max_size=3))
def test_any_lesson_loads_or_is_one_line(tmp_path, steps):
    from shadelab.lab.lesson_file import load_lesson

    path = tmp_path / "lesson.toml"
    try:
        path.write_text(tomli_w.dumps({"name": "fuzz", "steps": steps}), encoding="utf-8")
    except (TypeError, ValueError):
        return  # not expressible in TOML (tomli_w refuses it): no file a user could have
    try:
        load_lesson(str(path))
    except ShadeLabError as exc:
        _one_line(exc)


TASK_KEYS = st.sampled_from(["id", "kind", "title", "question", "preset", "set", "quantity",
                             "pixel", "tolerance", "options", "correct", "params", "target",
                             "region", "size", "light", "channel", "bogus"])


@SETTINGS
@given(tasks=st.lists(st.dictionaries(TASK_KEYS, VALUES.filter(lambda v: v is not None),
                                      max_size=5), min_size=0, max_size=3))
def test_any_exercise_loads_or_is_one_line(tmp_path, tasks):
    from shadelab.exercises.loader import load_exercise

    path = tmp_path / "exercise.toml"
    try:
        path.write_text(tomli_w.dumps({"name": "fuzz", "tasks": tasks}), encoding="utf-8")
    except (TypeError, ValueError):
        return
    try:
        load_exercise(str(path))
    except ShadeLabError as exc:
        _one_line(exc)
