"""The panels' shared widgets, colors and labels. Each dock window has its own module
(``scene_panel``, ``lights_panel``, ``materials_panel``, ``objects_panel``, ``equation_panel``,
``studies_panel``, ``offline``, ``render_panel``, ``radiosity_view``) whose
``draw_<x>_panel(state) -> bool`` returns True when it edited the scene.

Panels only read and write :class:`shadelab.lab.state.AppState`; GL work is asked for through it
(``state.probe.requested``, ``state.screenshot_requested``) and done by :mod:`shadelab.ui.app`.
"""

from __future__ import annotations

import numpy as np
from imgui_bundle import imgui

from shadelab.lab.state import AppState
from shadelab.shading.conventions import linear_to_srgb, srgb_to_linear
from shadelab.ui.ranges import finite, intensity_range

ERROR_COLOR = imgui.ImVec4(1.0, 0.35, 0.3, 1.0)
DIM_COLOR = imgui.ImVec4(0.65, 0.65, 0.65, 1.0)
OK_COLOR = imgui.ImVec4(0.4, 0.9, 0.4, 1.0)
SHADING_LABELS = {"flat": "Flat", "gouraud": "Gouraud", "phong": "Phong"}
SPECULAR_LABELS = {"phong": "Phong (R.V)^n", "blinn": "Blinn-Phong (N.H)^n"}



# ---------------------------------------------------------------- small widgets


def combo(label: str, value: str, choices: tuple[str, ...]) -> tuple[bool, str]:
    changed, index = imgui.combo(label, choices.index(value), list(choices))
    return changed, choices[index]


def shown_color(value) -> tuple[float, float, float]:
    """What a colour picker shows for a linear RGB value: the colour as it appears on screen
    (sRGB-encoded, as the frame is)."""
    return tuple(float(c) for c in linear_to_srgb(value))


def stored_color(shown) -> tuple[float, float, float]:
    """The linear RGB a picker's edited (on-screen, sRGB) colour stands for."""
    return tuple(float(c) for c in srgb_to_linear(shown))


def rgb_color(label: str, value) -> tuple[bool, tuple[float, float, float]]:
    """A colour picker on a linear RGB value (presets and the equation are linear): it shows
    and edits the colour as it appears on screen; an untouched value is returned as it was,
    a typed nan, inf or 1e309 is refused (the old value kept)."""
    changed, rgb = imgui.color_edit3(label, list(shown_color(value)),
                                     imgui.ColorEditFlags_.float)
    if not changed:
        return False, tuple(float(c) for c in value)
    changed, rgb = finite(changed, tuple(float(c) for c in rgb), None)
    if not changed:
        return False, tuple(float(c) for c in value)
    return True, stored_color(rgb)


def intensity_color(label: str, value) -> tuple[bool, tuple[float, float, float]]:
    """An RGB of any size as a color (max channel 1) times an intensity (log slider)."""
    rgb = np.asarray(value, dtype=np.float64)
    scale = float(rgb.max())
    color = rgb / scale if scale > 0 else np.ones(3)
    imgui.push_id(label)
    changed_c, color = rgb_color(f"{label} color", tuple(color))
    changed_s, scale = finite(*imgui.slider_float(f"{label} intensity", scale, 0.0,
                                                  intensity_range(scale), "%.4g"), scale)
    imgui.pop_id()
    if changed_c or changed_s:
        return True, tuple(float(c) * scale for c in color)
    return False, tuple(value)


def slider(label: str, value: float, lo: float, hi: float, log: bool = False,
            fmt: str = "%.3f") -> tuple[bool, float]:
    flags = imgui.SliderFlags_.logarithmic if log else 0
    return finite(*imgui.slider_float(label, float(value), lo, hi, fmt, flags), value)


def vec3(label: str, value, speed: float) -> tuple[bool, tuple[float, float, float]]:
    changed, v = imgui.drag_float3(label, list(value), speed, 0.0, 0.0, "%.3g")
    return finite(changed, tuple(float(c) for c in v), tuple(value))


def edit_fields(obj, rows: list[tuple]) -> bool:
    """Draw ``(field, widget, *args)`` rows on ``obj``; returns True when any changed."""
    edited = False
    for name, widget, *args in rows:
        changed, value = widget(name, getattr(obj, name), *args)
        if changed:
            setattr(obj, name, value)
            edited = True
    return edited


def scene_span(state: AppState) -> float:
    """A length for drag speeds and glyphs: the distance from the eye to the target."""
    cam = state.scene.camera
    return float(np.linalg.norm(np.subtract(cam.target, cam.eye))) or 1.0
