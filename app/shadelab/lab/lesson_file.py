"""Lesson files and the walk through them: :class:`Step`, :class:`Lesson`, :func:`load_lesson`
and :class:`LessonRun` (data only: no state, no GL, no GUI). :mod:`shadelab.lab.lesson` shows
the steps in the viewer; the file format is described there."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from shadelab.errors import ShadeLabError
from shadelab.scene.model import Scene
from shadelab.scene.preset import load_preset, read_toml

STEP_KEYS = {"title", "caption", "preset", "set", "pipeline", "focus", "show", "controls"}
# View toggles a step may switch on (every other one is off while the step shows):
# A lesson step's ``show`` names and the ViewState fields they switch on (state.view).
SHOW_TOGGLES = {"compare": "compare", "diff": "diff_enabled", "normals": "show_normals",
                "wireframe": "show_wireframe", "patches": "radiosity_patches",
                "face_normals": "show_face_normals", "normal_diff": "show_normal_diff"}


def lessons_dir() -> Path:
    from shadelab.resources import presets_dir

    return Path(presets_dir()) / "lessons"


def is_lesson_file(path: str) -> bool:
    """A ``.toml`` file with ``[[steps]]`` and no ``schema_version``: a lesson, not a preset
    (so Open and drag-and-drop take either)."""
    p = Path(path)
    if p.suffix.lower() != ".toml" or not p.is_file():
        return False
    try:
        raw = read_toml(p)
    except ShadeLabError:
        return False
    return "steps" in raw and "schema_version" not in raw


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
    show: list[str] = field(default_factory=list)   # SHOW_TOGGLES names
    controls: list[str] = field(default_factory=list)  # dotted paths, shown on stage


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
        show = item.get("show", [])
        if not isinstance(show, list) or not all(isinstance(v, str) for v in show):
            raise ShadeLabError(f"{where}: steps[{i}]: 'show' must be a list of names")
        bad = [v for v in show if v not in SHOW_TOGGLES]
        if bad:
            raise ShadeLabError(f"{where}: steps[{i}]: show: unknown '{bad[0]}' "
                                f"(expected {', '.join(SHOW_TOGGLES)})")
        controls = item.get("controls", [])
        if not isinstance(controls, list) or not all(isinstance(c, str) for c in controls):
            raise ShadeLabError(f"{where}: steps[{i}]: 'controls' must be a list of dotted "
                                "paths such as \"materials.plastic.n\"")
        _check_pipeline_and_focus(where, i, item)
        preset = item["preset"]
        if not Path(preset).is_absolute() and preset.endswith(".toml"):
            preset = str(path.parent / preset)  # a preset file next to the lesson
        steps.append(Step(item["title"], item["caption"], preset, list(overrides),
                          str(item.get("pipeline", "")), str(item.get("focus", "")),
                          list(show), list(controls)))
    name = raw.get("name", path.stem)
    if not isinstance(name, str) or not name.strip():
        raise ShadeLabError(f"{where}: key 'name': expected a non-empty string")
    lesson = Lesson(name, steps, str(path))
    if check:
        for i, step in enumerate(lesson.steps):
            try:
                scene = step_scene(step)
                from shadelab.lab.controls import check_controls

                check_controls(scene, step.controls)
            except ShadeLabError as exc:
                raise ShadeLabError(f"{where}: steps[{i}] ('{step.title}'): {exc}") from None
    return lesson


def _check_pipeline_and_focus(where: str, i: int, item: dict) -> None:
    """A step's ``pipeline`` is one of shadelab.pipelines.names(); its ``focus`` names
    panels; both are strings (one line naming the step and the key otherwise)."""
    from shadelab import pipelines
    from shadelab.lab.panel_names import PANEL_LABELS, unknown_panel

    title = item.get("title", "")
    step = f"{where}: steps[{i}] ('{title}')"
    for key in ("pipeline", "focus"):
        if key in item and not isinstance(item[key], str):
            raise ShadeLabError(f"{step}: key '{key}': expected a string, got "
                                f"{type(item[key]).__name__} {item[key]!r}")
    pipeline = item.get("pipeline", "")
    if pipeline and pipeline not in pipelines.names():
        raise ShadeLabError(f"{step}: key 'pipeline': unknown '{pipeline}' (expected one of "
                            f"{', '.join(pipelines.names())})")
    focus = item.get("focus", "")
    word = unknown_panel(focus) if focus else None
    if word is not None:
        raise ShadeLabError(f"{step}: key 'focus': no panel '{word}' (expected one of "
                            f"{', '.join(PANEL_LABELS)})")


def step_scene(step: Step) -> Scene:
    return load_preset(step.preset, step.set)


@dataclass
class LessonRun:
    """A lesson being walked: which step is shown."""

    lesson: Lesson
    index: int = -1
    loaded: tuple | None = None      # (scene_version, scene.version) just after go_to loaded it

    @property
    def step(self) -> Step | None:
        return self.lesson.steps[self.index] if 0 <= self.index < len(self.lesson.steps) \
            else None

    def caption(self) -> str:
        step = self.step
        if step is None:
            return ""
        return f"{self.index + 1}/{len(self.lesson.steps)}  {step.title}\n{step.caption}"
