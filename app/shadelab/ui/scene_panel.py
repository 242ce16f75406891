"""The Scene window: file (open, save, presets, lessons), render settings, the compare
options and the viewer's display options (:func:`draw_scene_panel`)."""

from __future__ import annotations

from pathlib import Path

from imgui_bundle import imgui

from shadelab.lab.state import COMPARE_LABELS, AppState
from shadelab.scene.model import (
    NORMALS_MODES,
    SHADING_MODES,
    SPECULAR_MODELS,
    RenderSettings,
)
from shadelab.scene.preset import list_presets
from shadelab.ui import dialogs, presenter
from shadelab.ui.layout import same_line_if_fits
from shadelab.ui.panels import (
    DIM_COLOR,
    ERROR_COLOR,
    SHADING_LABELS,
    SPECULAR_LABELS,
    combo,
    edit_fields,
    intensity_color,
    slider,
)
from shadelab.ui.ranges import field_slider

# ---------------------------------------------------------------- scene / file panel


def _is_shipped(path: str) -> bool:
    """True for a preset file that ShadeLab itself ships (never overwritten by Save)."""
    from pathlib import Path

    from shadelab.resources import presets_dir

    try:
        return Path(path).resolve().is_relative_to(presets_dir().resolve())
    except OSError:
        return False


def save_here(state: AppState) -> None:
    """Save (Ctrl+S): over the file the scene came from, unless nothing was saved yet or it is
    a preset ShadeLab ships, which are never overwritten: then ask where (Save as)."""
    target = state.preset_path or state.open_path
    if target and not _is_shipped(target):
        state.save_as(target)
    else:
        dialogs.ask(state, "save")


def draw_lesson_row(state: AppState) -> None:
    """Pick a shipped lesson (its Prev / Next buttons sit under the viewport's caption;
    PageUp / PageDown do the same); (none) ends it and keeps the scene."""
    from shadelab.lab import lesson

    run = state.walk.lesson
    current = "" if run is None else Path(run.lesson.path).stem
    if imgui.begin_combo("Lesson", current or "(none)"):
        if imgui.selectable("(none)", run is None)[0]:
            state.walk.lesson = None                    # the scene stays as it is
        for name in lesson.list_lessons():
            if imgui.selectable(name, name == current)[0]:
                state.request_open(str(lesson.lessons_dir() / f"{name}.toml"))
        imgui.end_combo()


def draw_file_panel(state: AppState) -> bool:
    """Open a preset from the list or a file; save; undo/redo."""
    if state.error:
        imgui.push_text_wrap_pos(0.0)
        imgui.text_colored(ERROR_COLOR, f"Error: {state.error}")
        imgui.pop_text_wrap_pos()
        if imgui.small_button("Dismiss"):
            state.error = ""
    presets = list_presets()
    current = state.scene.name if state.scene.name in presets else ""
    if imgui.begin_combo("Preset", current or "(file)"):
        for name in presets:
            if imgui.selectable(name, name == current)[0]:
                state.request_open(name)  # asks first when there are unsaved edits
        imgui.end_combo()
    draw_lesson_row(state)
    # Native dialogs first (what a user reaches for), then a typed path for scripts and tests.
    for label, purpose in (("Open...", "open"), ("Save", "save-here"), ("Save as...", "save"),
                           ("Add mesh...", "mesh")):
        if purpose != "open" and same_line_if_fits(label):
            imgui.same_line()
        if not imgui.button(label):
            continue
        if purpose == "save-here":
            save_here(state)
        else:
            dialogs.ask(state, purpose)
    _, state.open_path = imgui.input_text("File", state.open_path)
    if imgui.button("Open file"):
        state.request_open(state.open_path)  # a preset replaces the scene; a mesh is added
    if same_line_if_fits("Save to file"):
        imgui.same_line()
    if imgui.button("Save to file"):
        state.save_as(state.open_path)
    imgui.begin_disabled(not state.history.can_undo())
    if imgui.button("Undo (Ctrl+Z)"):
        state.undo()
    imgui.end_disabled()
    imgui.same_line()
    imgui.begin_disabled(not state.history.can_redo())
    if imgui.button("Redo (Ctrl+Y)"):
        state.redo()
    imgui.end_disabled()
    if state.status:
        imgui.push_style_color(imgui.Col_.text, DIM_COLOR)
        imgui.text_wrapped(state.status)           # long lesson titles wrap, never clip
        imgui.pop_style_color()
    return False


def draw_render_panel(state: AppState) -> bool:
    """Shading mode, specular model, exposure, ambient, overlays."""
    scene, edited = state.scene, False
    from shadelab.ui.render_panel import draw_pipeline_selector

    draw_pipeline_selector(state)
    imgui.text("Shading")
    for mode in SHADING_MODES:
        if same_line_if_fits(SHADING_LABELS[mode], radio=True):
            imgui.same_line()
        if imgui.radio_button(SHADING_LABELS[mode], scene.render.shading == mode):
            scene.render.shading, edited = mode, True
    imgui.text("Specular")
    for model in SPECULAR_MODELS:
        if same_line_if_fits(SPECULAR_LABELS[model], radio=True):
            imgui.same_line()
        if imgui.radio_button(SPECULAR_LABELS[model], scene.render.specular == model):
            scene.render.specular, edited = model, True
    edited |= edit_fields(scene.render, [("exposure", field_slider(RenderSettings))])
    edited |= edit_fields(scene, [("Ia", intensity_color)])
    _, state.view.show_wireframe = imgui.checkbox("Wireframe (W)", state.view.show_wireframe)
    imgui.same_line()
    _, state.view.show_normals = imgui.checkbox("Vertex normals (N)", state.view.show_normals)
    if same_line_if_fits("Face normals", radio=True):
        imgui.same_line()
    _, state.view.show_face_normals = imgui.checkbox("Face normals",
                                                     state.view.show_face_normals)
    if state.view.show_normals or state.view.show_face_normals:
        _, state.view.normal_length = slider("glyph length", state.view.normal_length,
                                              0.005, 0.3, True)
    draw_normal_heat_map_options(state)
    _, state.view.show_values = imgui.checkbox("Values", state.view.show_values)
    if imgui.is_item_hovered():
        imgui.set_tooltip("a figure's kd / ka / ks, n (and a pane's kt) under each object")
    if same_line_if_fits("Names", radio=True):
        imgui.same_line()
    _, state.view.show_names = imgui.checkbox("Names", state.view.show_names)
    changed, mode = combo("normals (all)", "", ("",) + NORMALS_MODES)
    if changed and mode:
        for obj in scene.objects:
            obj.normals = mode
        edited = True
    return edited


def draw_normal_heat_map_options(state: AppState) -> None:
    """The angle between two vertex-normal rules, painted on the surfaces in degrees."""
    from shadelab.geometry.normals import VERTEX_MODES

    view = state.view
    _, view.show_normal_diff = imgui.checkbox("Normal heat map", view.show_normal_diff)
    if imgui.is_item_hovered():
        imgui.set_tooltip("colour = angle in degrees between the vertex normals of two rules")
    if not view.show_normal_diff:
        return
    a, b = view.normal_diff_modes
    _, ia = imgui.combo("rule A", VERTEX_MODES.index(a), list(VERTEX_MODES))
    _, ib = imgui.combo("rule B", VERTEX_MODES.index(b), list(VERTEX_MODES))
    view.normal_diff_modes = (VERTEX_MODES[ia], VERTEX_MODES[ib])


# ---------------------------------------------------------------- compare options


def draw_compare_panel(state: AppState) -> bool:
    """2x2 compare mode and the difference heat map between any two views."""
    _, state.view.compare = imgui.checkbox("Compare 2x2 (C)", state.view.compare)
    if not state.view.compare:
        return False
    _, state.view.diff_enabled = imgui.checkbox("Difference heat map", state.view.diff_enabled)
    a, b = state.view.diff_pair
    _, a = imgui.combo("A", a, list(COMPARE_LABELS))
    _, b = imgui.combo("B", b, list(COMPARE_LABELS))
    state.view.diff_pair = (a, b)
    _, state.view.diff_scale = slider("full scale |A-B|", state.view.diff_scale, 1e-4, 1.0,
                                       True, "%.4g")
    return False


def screenshot(state: AppState) -> None:
    """Ask for a viewport screenshot (S): the next free shadelab-<scene>-NNN.png."""
    name = state.scene.name or "scene"
    folder = Path(state.screenshot_dir)
    index = 1
    while (folder / f"shadelab-{name}-{index:03d}.png").exists():
        index += 1
    state.screenshot_requested = str(folder / f"shadelab-{name}-{index:03d}.png")


def draw_scene_panel(state: AppState) -> bool:
    """The Scene window."""
    draw_file_panel(state)
    imgui.separator()
    edited = draw_render_panel(state)
    imgui.separator()
    draw_compare_panel(state)
    changed, on = imgui.checkbox("Presenter mode (F)", state.view.presenter)
    if changed:   # on: the stage (the panels hidden, Tab brings them back)
        presenter.set_presenter(state, on)
    imgui.same_line()
    _, state.view.show_help = imgui.checkbox("Help (H)", state.view.show_help)
    if imgui.button("Screenshot (S)"):
        screenshot(state)
    imgui.same_line()
    _, state.view.legend_in_screenshot = imgui.checkbox("with legend",
                                                        state.view.legend_in_screenshot)
    if imgui.button("Reset view (R)"):
        state.reset_view()
    _, state.view.render_scale = slider("render scale", state.view.render_scale, 0.25, 1.0)
    _, state.view.interactive_scale = slider("while dragging", state.view.interactive_scale,
                                             0.25, 1.0)
    edited |= presenter.draw_display_panel(state)
    return edited
