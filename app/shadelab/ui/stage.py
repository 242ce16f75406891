"""The stage (issue 22): in presenter mode the viewport takes the window and the lesson step's
controls (``controls = [...]`` in the lesson file, :mod:`shadelab.lab.controls`) sit large in
a strip under its caption; Tab (the strip's last button) brings the dock panels back.

The strip keeps one height for the whole lesson (the scene never moves between steps); its
widgets are the panels' (slider ranges from :mod:`shadelab.ui.ranges`, a checkbox for a
switch, a combo for a choice, a colour for an RGB) and an edit goes through the scene model's
validation and ``state.mark_edited()`` (undo, autosave, the probe), as a panel's does.
"""

from __future__ import annotations

import math

import numpy as np
from imgui_bundle import imgui

from shadelab.errors import ShadeLabError
from shadelab.lab.controls import Control, resolve, set_value
from shadelab.lab.state import AppState
from shadelab.ui.panels import DIM_COLOR, shown_color, stored_color
from shadelab.ui.ranges import intensity_range, slider_range, spec_range

STRIP_PAD = 6.0          # pixels around the strip's row, at font scale 1 (grows with it)
STRIP_BG = 0xFF161616
PANELS_BUTTON = "All panels (Tab)"
STEP_BUTTONS = ("< PgUp", "PgDn >")   # the lesson's previous / next step
# The controls the last strip drew, [(path, widget, item id)], only while a GUI test sets
# RECORD (the tests find and drive the widgets by these ids)
RECORD = False
drawn_controls: list = []


def lesson_has_controls(state: AppState) -> bool:
    run = state.walk.lesson
    return run is not None and run.step is not None \
        and any(step.controls for step in run.lesson.steps)


def strip_height(state: AppState) -> float:
    """The strip's height under the viewport: on stage (panels hidden) in a lesson that names
    controls, a label row (the step buttons at its right) and a widget row, the same at
    every step; else 0."""
    if not state.view.hide_panels or not lesson_has_controls(state):
        return 0.0
    return (imgui.get_frame_height_with_spacing() + imgui.get_frame_height() + 2 * _pad())


def _pad() -> float:
    return STRIP_PAD * imgui.get_style().font_scale_main


def step_controls(state: AppState) -> list[str]:
    run = state.walk.lesson
    return list(run.step.controls) if run is not None and run.step is not None else []


def draw_strip(state: AppState, origin, width: float, height: float) -> bool:
    """The step's controls in equal columns across ``width`` at ``origin`` (screen), each
    label over its widget, and the panels button at the right; True when one edited the
    scene (marked edited here)."""
    if height <= 0:
        return False
    if RECORD:
        drawn_controls.clear()
    style = imgui.get_style()
    pad = _pad()
    draw = imgui.get_window_draw_list()
    draw.add_rect_filled(origin, imgui.ImVec2(origin.x + width, origin.y + height), STRIP_BG)
    button_w = imgui.calc_text_size(PANELS_BUTTON).x + 2 * style.frame_padding.x
    paths = step_controls(state)
    gap = 2 * style.item_spacing.x
    room = width - button_w - 2 * pad - gap
    column = (room - gap * max(len(paths) - 1, 0)) / max(len(paths), 1)
    label_y = origin.y + pad
    widget_y = label_y + imgui.get_frame_height_with_spacing()
    text_dy = style.frame_padding.y          # labels level with the step buttons' text
    edited = False
    for i, path in enumerate(paths):
        x = origin.x + pad + i * (column + gap)
        imgui.push_id(path)
        try:
            control = resolve(state.scene, path)
        except ShadeLabError:
            imgui.set_cursor_screen_pos(imgui.ImVec2(x, label_y + text_dy))
            imgui.text_colored(DIM_COLOR, f"{path}: not in this scene")
            imgui.pop_id()
            continue
        imgui.set_cursor_screen_pos(imgui.ImVec2(x, label_y + text_dy))
        imgui.text(control.label)
        imgui.set_cursor_screen_pos(imgui.ImVec2(x, widget_y))
        imgui.push_item_width(column)
        try:
            edited |= _widget(state, control, column)
        finally:
            imgui.pop_item_width()
            imgui.pop_id()
        if RECORD:
            drawn_controls.append((path, control.widget, imgui.get_item_id()))
    bx = origin.x + width - pad - button_w
    _step_buttons(state, bx, label_y, button_w)
    imgui.set_cursor_screen_pos(imgui.ImVec2(bx, widget_y))
    if imgui.button(PANELS_BUTTON):
        state.view.hide_panels = False
    if edited:
        state.mark_edited()
    return edited


def _step_buttons(state: AppState, x: float, y: float, width: float) -> None:
    """Previous / next step, side by side in ``width`` (PageUp / PageDown do the same)."""
    from shadelab.lab import lesson

    gap = imgui.get_style().item_spacing.x
    half = (width - gap) / 2
    imgui.set_cursor_screen_pos(imgui.ImVec2(x, y))
    if imgui.button(STEP_BUTTONS[0], imgui.ImVec2(half, 0)):
        lesson.previous_step(state)
    imgui.same_line(0, gap)
    if imgui.button(STEP_BUTTONS[1], imgui.ImVec2(half, 0)):
        lesson.next_step(state)


def _write(state: AppState, control: Control, value) -> bool:
    try:
        return set_value(control, value)
    except ShadeLabError as exc:   # the model refused it: say so, keep the value
        state.error = str(exc)
        return False


def _widget(state: AppState, control: Control, width: float) -> bool:
    """The control's widget (label hidden: the strip draws it above); True when it wrote."""
    value = control.value()
    kind = control.kind
    if kind == "float":
        lo, hi, log, fmt = slider_range(control.cls, control.field, float(value))
        flags = imgui.SliderFlags_.logarithmic if log else 0
        changed, new = imgui.slider_float("##value", float(value), lo, hi, fmt, flags)
        if changed and math.isfinite(new):
            spec_lo, spec_hi = spec_range(control.cls, control.field)
            return _write(state, control, float(min(max(new, spec_lo), spec_hi)))
        return False
    if kind == "int":
        lo, hi = (int(v) for v in control.args)
        flags = imgui.SliderFlags_.logarithmic if hi - lo > 1000 else 0
        changed, new = imgui.slider_int("##value", int(value), lo, hi, "%d", flags)
        return _write(state, control, int(min(max(new, lo), hi))) if changed else False
    if kind == "bool":
        changed, new = imgui.checkbox("on##value" if value else "off##value", bool(value))
        return _write(state, control, bool(new)) if changed else False
    if kind == "str":
        choices = list(control.args[0])
        index = choices.index(value) if value in choices else 0
        changed, index = imgui.combo("##value", index, choices)
        return _write(state, control, choices[index]) if changed else False
    return _color(state, control, value, width)


def _color(state: AppState, control: Control, value, width: float) -> bool:
    """rgb01: a colour edit; rgb (intensities): a swatch of the colour and a slider of its
    brightness on one row (the Lights panel's colour times intensity)."""
    rgb = np.asarray(value, dtype=np.float64)
    flags = imgui.ColorEditFlags_.float | imgui.ColorEditFlags_.no_label
    if control.kind == "rgb01":
        changed, shown = imgui.color_edit3("##value", list(shown_color(rgb)), flags)
        return _write(state, control, stored_color(shown)) if changed else False
    scale = float(rgb.max())
    color = rgb / scale if scale > 0 else np.ones(3)
    changed_c, shown = imgui.color_edit3("##color", list(shown_color(color)),
                                         flags | imgui.ColorEditFlags_.no_inputs)
    imgui.same_line()
    imgui.set_next_item_width(max(width - imgui.get_frame_height()
                                  - imgui.get_style().item_spacing.x, 40.0))
    changed_s, new_scale = imgui.slider_float("##value", scale, 0.0,
                                              intensity_range(scale), "%.3g")
    if changed_c:
        color = np.asarray(stored_color(shown))
    if changed_s and math.isfinite(new_scale):
        scale = new_scale
    if changed_c or changed_s:
        return _write(state, control, tuple(float(c) * scale for c in color))
    return False
