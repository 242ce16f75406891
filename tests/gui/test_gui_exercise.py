"""The Exercise window answered through its widgets, one task of each kind (number, choice,
match, pixel): a right answer passes, a wrong one fails, and the window's verdict equals the
headless grading of the same answer (issue 23).

Run one scenario by hand:  xvfb-run -a python3 tests/gui/test_gui_exercise.py kinds /tmp/out
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/: gui_harness
from test_gui import _wait, imgui_vec, run_scenario  # noqa: E402
from test_gui import xdisplay as _xdisplay_fixture  # noqa: E402

xdisplay = _xdisplay_fixture    # the private Xvfb server (a pytest fixture)

from gui_harness import run_scenario_main  # noqa: E402

pytestmark = pytest.mark.gui
EXERCISE = "phong-to-radiosity"


def test_one_task_of_each_kind_answered_in_the_window(xdisplay, tmp_path):
    r = run_scenario("kinds", xdisplay, tmp_path, script=__file__, timeout=300)
    assert set(r) >= {"number", "choice", "match", "pixel"}, r
    for kind in ("number", "choice", "match", "pixel"):
        right, wrong = r[kind]["right"], r[kind]["wrong"]
        assert right["window"] == "pass" and wrong["window"] == "fail", (kind, r[kind])
        # the window grades as `shadelab exercise --answers` does, answer for answer
        assert right["window"] == right["headless"] and wrong["window"] == wrong["headless"]


# ---------------------------------------------------------------- script side


def _submit(ctx, state, panel, task) -> str:
    ts = panel.task_state(task)
    ts.result = None
    ctx.item_click("Submit")
    _wait(ctx, lambda: ts.result is not None)
    return ts.result.verdict if ts.result is not None else "none"


def _headless(task, answer) -> str:
    from shadelab.exercises.headless import api_render

    task.render = api_render
    return task.grade(answer).verdict


def scenario_kinds(ctx, state, out: dict) -> None:
    from shadelab.exercises.loader import load_exercise
    from shadelab.ui.exercise_panel import open_exercise, panel_of

    open_exercise(state, load_exercise(EXERCISE))
    ctx.yield_(3)
    panel = panel_of(state)
    ctx.set_ref("//Exercise")
    ctx.window_focus("//Exercise")
    done = set()
    for index, task in enumerate(panel.exercise.tasks):
        kind = task.KIND
        if kind in done or kind not in ("number", "choice", "match", "pixel"):
            continue
        panel.index = index
        ctx.yield_(3)
        ready = _wait(ctx, lambda t=task: _try_expected(t) is not None, frames=900)
        if not ready:
            out[kind] = {"error": "no expected value"}
            continue
        expected = _try_expected(task)
        ts = panel.task_state(task)
        rows = {}
        for label, answer in (("right", _right(task, expected)), ("wrong", _wrong(task,
                                                                               expected))):
            if kind == "number":
                ctx.item_input_value("your answer", float(answer))
            elif kind == "choice":
                ctx.item_click(str(answer))
            elif kind == "match":
                for key, value in zip(task.params, answer, strict=True):
                    ctx.item_input_value(key, float(value))
            else:   # pixel: click the picture where the answer is
                name = f"pick:{task.id}"
                _wait(ctx, lambda n=name: n in panel.image_rects)
                x0, y0, scale = panel.image_rects[name]
                ctx.mouse_move_to_pos(imgui_vec(x0 + (answer[0] + 0.5) * scale,
                                                y0 + (answer[1] + 0.5) * scale))
                ctx.mouse_click(0)
            ctx.yield_(2)
            given = ts.answer
            rows[label] = {"window": _submit(ctx, state, panel, task),
                           "headless": _headless(task, given), "answer": repr(given)}
        out[kind] = rows
        done.add(kind)


def _try_expected(task):
    from shadelab.exercises.tasks import NeedImages

    try:
        return task.expected()
    except NeedImages:
        return None


def _right(task, expected):
    return expected.value


def _wrong(task, expected):
    kind = task.KIND
    if kind == "number":
        return float(expected.value) + 10.0 * max(expected.tolerance or 0.0, 0.1) + 1.0
    if kind == "choice":
        letters = [letter for letter, _, _ in task.shown()]
        return next(letter for letter in letters if letter != expected.value)
    if kind == "match":
        return [lo for lo, _ in task.ranges]
    x, y = expected.value
    w, h = task.size
    return (w - 1 - x if abs(w - 1 - 2 * x) > 4 * expected.tolerance + 2 else 0,
            h - 1 - y if abs(h - 1 - 2 * y) > 4 * expected.tolerance + 2 else 0)


def _main(name: str, out_dir: str) -> int:
    return run_scenario_main(globals(), name, out_dir, "lecture", (1280, 800))


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1], sys.argv[2]))
