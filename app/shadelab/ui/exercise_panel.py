"""The Exercise dock window: predict, then reveal (shadelab.exercises).

Student mode hides the lab's value until an answer is submitted and counts the attempts; a
hint is one click away. Teacher mode shows the value from the start. Images are drawn by the
viewer's GL side through ``state.gpu`` ("raster" requests), never here; probe, ray-tree and
form-factor values are computed on the CPU when the answer is submitted. Text wraps, so the
window stays readable in a 1024x768 presenter layout.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from imgui_bundle import imgui

from shadelab.errors import ShadeLabError
from shadelab.exercises import Exercise, NeedImages, Result, list_exercises, load_exercise
from shadelab.exercises.tasks import ChoiceTask, MatchTask, NumberTask, PixelTask, Shot
from shadelab.shading.conventions import to_srgb8

PASS_COLOR = imgui.ImVec4(0.4, 0.9, 0.4, 1.0)
FAIL_COLOR = imgui.ImVec4(1.0, 0.45, 0.35, 1.0)
KEY = "exercise:"


@dataclass
class TaskState:
    answer: object = None
    attempts: int = 0
    result: Result | None = None
    show_hint: bool = False
    waiting: bool = False     # submitted; the images it needs are being drawn
    reveal: list[str] = field(default_factory=list)
    reveal_images: dict = field(default_factory=dict)


@dataclass
class ExercisePanel:
    exercise: Exercise | None = None
    index: int = 0
    teacher: bool = False
    tasks: dict[str, TaskState] = field(default_factory=dict)
    error: str = ""
    pending: set[str] = field(default_factory=set)   # gpu request keys waiting
    choice: int = 0
    uploaded: set[str] = field(default_factory=set)  # textures already sent (not per frame)
    class_dir: str = ""                              # teacher: the class's graded records
    class_rows: dict = field(default_factory=dict)   # task id -> grading.ClassRow
    image_rects: dict = field(default_factory=dict)  # image name -> (x, y, scale) on screen

    def task_state(self, task) -> TaskState:
        return self.tasks.setdefault(task.id, TaskState())


_PANELS: dict[int, ExercisePanel] = {}


def panel_of(state) -> ExercisePanel:
    return _PANELS.setdefault(id(state), ExercisePanel())


def open_exercise(state, exercise: Exercise) -> None:
    """Show ``exercise`` in the Exercise window (``shadelab view --exercise``)."""
    panel = panel_of(state)
    panel.exercise, panel.index, panel.tasks, panel.error = exercise, 0, {}, ""
    panel.class_rows = {}
    state.walk.focus_request = "Exercise"  # brought to the front on the next frame


# ---------------------------------------------------------------- images via state.gpu


def _collect(state, panel: ExercisePanel, task) -> None:
    """Take the renders the GL side finished into the task."""
    for key in list(panel.pending):
        shot_key = key[len(KEY):]
        if key in state.gpu.errors:
            panel.error = state.gpu.errors.pop(key)
            panel.pending.discard(key)
            continue
        image = state.gpu.take(key)
        if image is not None:
            task.images[shot_key] = np.asarray(image, np.float32)
            panel.pending.discard(key)


def _ask(state, panel: ExercisePanel, shots: dict[str, Shot]) -> None:
    for key, shot in shots.items():
        gpu_key = KEY + key
        if gpu_key in panel.pending:
            continue
        state.gpu.request(gpu_key, "raster", scene=shot.scene(), size=shot.size,
                          shading=shot.shading or None, specular=shot.specular or None)
        panel.pending.add(gpu_key)


def _try(state, panel: ExercisePanel, task, call):
    """Run ``call``; images it still needs are requested (None until they arrive)."""
    try:
        return call()
    except NeedImages as need:
        _ask(state, panel, need.shots)
        return None
    except ShadeLabError as exc:
        panel.error = str(exc)
        return None


def _show(state, name: str, image: np.ndarray, width: float):
    """Show a linear image ``width`` pixels wide (uploaded once); returns the clicked (x, y)
    of the image."""
    key = f"{KEY}img:{name}"
    uploaded = panel_of(state).uploaded
    if key not in uploaded:
        state.gpu.upload(key, to_srgb8(np.asarray(image)))
        uploaded.add(key)
    texture = state.gpu.texture(key)
    h, w = image.shape[:2]
    scale = width / w
    if texture is None:
        imgui.dummy(imgui.ImVec2(width, h * scale))
        return None
    origin = imgui.get_cursor_screen_pos()
    panel_of(state).image_rects[name] = (origin.x, origin.y, scale)  # where a click lands
    imgui.image(imgui.ImTextureRef(texture.id), imgui.ImVec2(width, h * scale))
    if imgui.is_item_clicked():
        mouse = imgui.get_io().mouse_pos
        return int((mouse.x - origin.x) / scale), int((mouse.y - origin.y) / scale)
    return None


# ---------------------------------------------------------------- the window


def draw_exercise_panel(state) -> bool:
    panel = panel_of(state)
    names = list_exercises()
    if panel.exercise is None and names:
        label = "Open an exercise..."
    else:
        label = panel.exercise.name if panel.exercise else "(none shipped)"
    if imgui.begin_combo("exercise", label):
        for name in names:
            if imgui.selectable(name, False)[0]:
                try:
                    open_exercise(state, load_exercise(name))
                except ShadeLabError as exc:
                    panel.error = str(exc)
        imgui.end_combo()
    _, panel.teacher = imgui.checkbox("Teacher mode (show the answers)", panel.teacher)
    if panel.error:
        imgui.text_colored(FAIL_COLOR, "")
        imgui.same_line()
        imgui.text_wrapped(panel.error)
    exercise = panel.exercise
    if exercise is None:
        imgui.text_wrapped("Pick an exercise: each task asks for a prediction, grades it "
                           "against the lab's own value and reveals why.")
        return False
    n = len(exercise.tasks)
    panel.index = min(max(panel.index, 0), n - 1)
    task = exercise.tasks[panel.index]
    ts = panel.task_state(task)
    _collect(state, panel, task)
    if imgui.button("< Prev") and panel.index > 0:
        panel.index -= 1
    imgui.same_line()
    if imgui.button("Next >") and panel.index < n - 1:
        panel.index += 1
    imgui.same_line()
    done = sum(1 for s in panel.tasks.values() if s.result is not None and s.result.passed)
    imgui.text(f"{panel.index + 1}/{n}   passed {done}")
    imgui.separator()
    imgui.text_wrapped(task.title)
    imgui.text_wrapped(task.question)
    if task.hint:
        if imgui.small_button("Hint"):
            ts.show_hint = not ts.show_hint
        if ts.show_hint:
            imgui.text_wrapped(f"Hint: {task.hint}")
    width = max(imgui.get_content_region_avail().x, 64.0)
    if panel.teacher:
        expected = _try(state, panel, task, task.expected)
        if expected is not None:
            tol = "" if expected.tolerance is None else f" +/- {expected.tolerance:g}"
            imgui.text_wrapped(f"Answer: {task.answer_text(expected.value)}{tol}")
        _draw_class(panel, task)
    _draw_answer(state, panel, task, ts, width)
    submit = imgui.button("Submit") and ts.answer is not None
    if ts.answer is None:
        imgui.same_line()
        imgui.text_disabled("(answer first)")
    if submit or ts.waiting:
        result = _try(state, panel, task, lambda: task.grade(ts.answer))
        ts.waiting = result is None and bool(panel.pending)
        if result is not None:
            ts.attempts += 1
            ts.result = result
            revealed = _try(state, panel, task, lambda: task.reveal(result))
            if revealed is not None:
                ts.reveal, ts.reveal_images = revealed.lines, revealed.images
                panel.uploaded = {k for k in panel.uploaded
                                  if not k.startswith(f"{KEY}img:reveal:{task.id}:")}
    imgui.same_line()
    imgui.text(f"attempts: {ts.attempts}")
    if ts.result is not None:
        color = PASS_COLOR if ts.result.passed else FAIL_COLOR
        imgui.text_colored(color, ts.result.verdict.upper())
        imgui.same_line()
        imgui.text_wrapped(ts.result.message)
        for line in ts.reveal:
            imgui.text_wrapped(line)
        for name, image in ts.reveal_images.items():
            imgui.text(name)
            _show(state, f"reveal:{task.id}:{name}", image, min(width, 2.0 * image.shape[1]))
    return False


def load_class(panel: ExercisePanel, folder: str) -> None:
    """Teacher mode: the class's graded records (``shadelab exercise --json``) in ``folder``,
    summed per task (an error is one line in the panel)."""
    from shadelab.exercises.grading import class_summary, load_class_results

    try:
        panel.class_rows = class_summary(panel.exercise, load_class_results(folder))
        panel.class_dir, panel.error = folder, ""
    except ShadeLabError as exc:
        panel.class_rows, panel.error = {}, str(exc)


def _draw_class(panel: ExercisePanel, task) -> None:
    _, panel.class_dir = imgui.input_text("class results folder", panel.class_dir)
    imgui.same_line()
    if imgui.small_button("Load"):
        load_class(panel, panel.class_dir)
    row = panel.class_rows.get(task.id)
    if row is not None:
        imgui.text_wrapped(row.text())


def _draw_answer(state, panel: ExercisePanel, task, ts: TaskState, width: float) -> None:
    if isinstance(task, NumberTask):
        value = float(ts.answer) if ts.answer is not None else 0.0
        changed, value = imgui.input_double("your answer", value, 0.0, 0.0, "%.4f")
        if changed:
            ts.answer = value
        return
    if isinstance(task, ChoiceTask):
        shown = task.shown()
        _try(state, panel, task, lambda: task.need(task.shots()))
        columns = 2 if len(shown) > 1 else 1
        cell = (width - 8.0 * columns) / columns
        for i, (letter, _, shot) in enumerate(shown):
            if i % columns:
                imgui.same_line()
            imgui.begin_group()
            if imgui.radio_button(letter, ts.answer == letter):
                ts.answer = letter
            image = task.images.get(shot.key)
            if image is not None:
                if _show(state, f"choice:{task.id}:{letter}", image, cell) is not None:
                    ts.answer = letter
            else:
                imgui.text_disabled("rendering...")
            imgui.end_group()
        return
    if isinstance(task, MatchTask):
        values = list(ts.answer) if ts.answer is not None else list(task.start)
        for i, (key, (lo, hi)) in enumerate(zip(task.params, task.ranges, strict=True)):
            changed, v = imgui.slider_float(key, float(values[i]), lo, hi)
            if changed and math.isfinite(v):  # a typed nan / inf is refused
                values[i] = float(v)
        ts.answer = values
        target = task.target_shot()
        _try(state, panel, task, lambda: task.need({target.key: target}))
        image = task.images.get(target.key)
        if image is not None:
            imgui.text("target")
            _show(state, f"target:{task.id}", image, min(width, 2.0 * image.shape[1]))
        return
    if isinstance(task, PixelTask):
        base = task.base_shot()
        _try(state, panel, task, lambda: task.need({base.key: base}))
        image = task.images.get(base.key)
        if image is None:
            imgui.text_disabled("rendering...")
            return
        imgui.text("click the picture")
        clicked = _show(state, f"pick:{task.id}", image, min(width, 4.0 * image.shape[1]))
        if clicked is not None:
            x = min(max(clicked[0], 0), task.size[0] - 1)
            y = min(max(clicked[1], 0), task.size[1] - 1)
            ts.answer = (x, y)
        if ts.answer is not None:
            imgui.text(f"your pixel: {task.answer_text(ts.answer)}")
