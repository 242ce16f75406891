"""Lessons: an ordered list of steps (preset, overrides, pipeline, panel focus, caption) that
PageDown / PageUp walk through; the caption is shown large in the viewport.

A lesson is a TOML file in ``presets/lessons/`` (or a path)::

    name = "From the Phong model to radiosity"
    [[steps]]
    title = "Ambient light"
    caption = "I = Ia ka"          # one slide's equation
    preset = "lecture"
    set = ["lights.0.enabled=false"]   # --set overrides
    pipeline = "phong"             # optional; a pipeline the viewer lacks is skipped
    focus = "Materials"            # optional; panels brought to the front (comma-separated)

Loading a lesson checks every step (its preset loads with its overrides) so a typo fails at
start with one line, not in front of the class at step 7.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from shadelab.errors import ShadeLabError
from shadelab.scene.model import Scene
from shadelab.scene.preset import load_preset, read_toml

STEP_KEYS = {"title", "caption", "preset", "set", "pipeline", "focus"}


def lessons_dir() -> Path:
    from shadelab.resources import presets_dir

    return Path(presets_dir()) / "lessons"


def list_lessons() -> list[str]:
    return sorted(p.stem for p in lessons_dir().glob("*.toml"))


@dataclass
class Step:
    title: str
    caption: str
    preset: str
    set: list[str] = field(default_factory=list)
    pipeline: str = ""
    focus: str = ""


@dataclass
class Lesson:
    name: str
    steps: list[Step]
    path: str = ""


def resolve_lesson(name_or_path: str) -> Path:
    path = Path(name_or_path)
    if path.suffix == ".toml" or "/" in name_or_path:
        if not path.is_file():
            raise ShadeLabError(f"lesson '{name_or_path}': file not found")
        return path
    path = lessons_dir() / f"{name_or_path}.toml"
    if not path.is_file():
        raise ShadeLabError(f"lesson '{name_or_path}': expected one of "
                            f"{', '.join(list_lessons()) or '(none shipped)'}, or a .toml path")
    return path


def load_lesson(name_or_path: str, check: bool = True) -> Lesson:
    """Read and check a lesson file (every step's preset loads with its overrides)."""
    path = resolve_lesson(name_or_path)
    raw = read_toml(path)
    where = path.name
    steps_raw = raw.get("steps")
    if not isinstance(steps_raw, list) or not steps_raw:
        raise ShadeLabError(f"{where}: expected at least one [[steps]] table")
    steps = []
    for i, item in enumerate(steps_raw):
        if not isinstance(item, dict):
            raise ShadeLabError(f"{where}: steps[{i}]: expected a table")
        unknown = set(item) - STEP_KEYS
        if unknown:
            raise ShadeLabError(f"{where}: steps[{i}]: unknown key '{sorted(unknown)[0]}' "
                                f"(expected {', '.join(sorted(STEP_KEYS))})")
        for key in ("title", "caption", "preset"):
            if not isinstance(item.get(key), str) or not item[key]:
                raise ShadeLabError(f"{where}: steps[{i}]: '{key}' must be a non-empty string")
        overrides = item.get("set", [])
        if not isinstance(overrides, list) or not all(isinstance(s, str) for s in overrides):
            raise ShadeLabError(f"{where}: steps[{i}]: 'set' must be a list of KEY=VALUE strings")
        preset = item["preset"]
        if not Path(preset).is_absolute() and preset.endswith(".toml"):
            preset = str(path.parent / preset)  # a preset file next to the lesson
        steps.append(Step(item["title"], item["caption"], preset, list(overrides),
                          str(item.get("pipeline", "")), str(item.get("focus", ""))))
    lesson = Lesson(str(raw.get("name", path.stem)), steps, str(path))
    if check:
        for i, step in enumerate(lesson.steps):
            try:
                step_scene(step)
            except ShadeLabError as exc:
                raise ShadeLabError(f"{where}: steps[{i}] ('{step.title}'): {exc}") from None
    return lesson


def step_scene(step: Step) -> Scene:
    return load_preset(step.preset, step.set)


@dataclass
class LessonRun:
    """A lesson being walked: which step is shown."""

    lesson: Lesson
    index: int = -1

    @property
    def step(self) -> Step | None:
        return self.lesson.steps[self.index] if 0 <= self.index < len(self.lesson.steps) \
            else None

    def caption(self) -> str:
        step = self.step
        if step is None:
            return ""
        return f"{self.index + 1}/{len(self.lesson.steps)}  {step.title}\n{step.caption}"


def go_to(state, index: int) -> bool:
    """Show step ``index`` of ``state.lesson`` (clamped); the load is undoable."""
    run = state.lesson
    if run is None:
        return False
    index = max(0, min(index, len(run.lesson.steps) - 1))
    step = run.lesson.steps[index]
    try:
        scene = step_scene(step)
        from shadelab.geometry.mesh import scene_meshes

        scene_meshes(scene)
    except ShadeLabError as exc:
        state.error = f"lesson step {index + 1}: {exc}"
        return False
    run.index = index
    state.replace_scene(scene, step.preset, new_file=True)
    state.pending_open = ""
    apply_pipeline(state, step.pipeline)
    if step.focus:
        state.focus_request = step.focus
    state.error, state.status = "", f"lesson step {index + 1}/{len(run.lesson.steps)}: " \
                                     f"{step.title}"
    return True


def apply_pipeline(state, name: str) -> None:
    """Select the step's pipeline where the viewer has one (ui/pipelines); the raster ones
    fall back to the scene's shading mode."""
    if not name:
        return
    try:
        from shadelab.ui import pipelines
    except ImportError:
        pipelines = None
    if pipelines is not None and hasattr(state, "pipeline") \
            and name in getattr(pipelines, "PIPELINES", ()):
        pipelines.set_pipeline(state, name)
        return
    if name in ("flat", "gouraud", "phong"):
        state.scene.render.shading = name


def next_step(state) -> None:
    if state.lesson is not None:
        go_to(state, state.lesson.index + 1)


def previous_step(state) -> None:
    if state.lesson is not None:
        go_to(state, state.lesson.index - 1)
