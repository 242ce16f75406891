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
    show = ["compare"]             # optional; view toggles on for this step (compare, diff,
                                   # normals, wireframe, patches), the others off
    controls = ["materials.plastic.ka", "Ia"]  # optional, at most 4: the parameters the
                                   # slide is about (--set paths), shown large on stage

Loading a lesson checks every step (its preset loads with its overrides) so a typo fails at
start with one line, not in front of the class at step 7.
"""

from __future__ import annotations

from shadelab.errors import ShadeLabError

# The file format and the walk (data only), re-exported where the viewer has always found them
from shadelab.lab.lesson_file import (  # noqa: F401
    SHOW_TOGGLES,
    STEP_KEYS,
    Lesson,
    LessonRun,
    Step,
    lessons_dir,
    list_lessons,
    load_lesson,
    resolve_lesson,
    step_scene,
)


def go_to(state, index: int) -> bool:
    """Show step ``index`` of ``state.walk.lesson`` (clamped); the load is undoable."""
    run = state.walk.lesson
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
    for name, attr in SHOW_TOGGLES.items():
        setattr(state.view, attr, name in step.show)
    state.view.terms_off = frozenset()   # every step starts from the whole equation
    if step.focus:
        state.walk.focus_request = step.focus
    run.loaded = (state.scene_version, state.scene.version)   # prefetch key: till an edit
    state.error, state.status = "", f"lesson step {index + 1}/{len(run.lesson.steps)}: " \
                                     f"{step.title}"
    return True


def apply_pipeline(state, name: str) -> None:
    """Select the step's pipeline where the viewer has one (ui/pipelines); the raster ones
    fall back to the scene's shading mode."""
    if not name:
        return
    from shadelab.lab import pipeline_view

    if name in pipeline_view.PIPELINES:
        pipeline_view.set_pipeline(state, name)
        return
    if name in ("flat", "gouraud", "phong"):
        state.scene.render.shading = name


def next_step(state) -> None:
    if state.walk.lesson is not None:
        go_to(state, state.walk.lesson.index + 1)


def previous_step(state) -> None:
    if state.walk.lesson is not None:
        go_to(state, state.walk.lesson.index - 1)
