"""The Objects window: each object's material, normals, tessellation and transform
(:func:`draw_objects_panel`)."""

from __future__ import annotations

import math

from imgui_bundle import imgui

from shadelab.lab.state import AppState
from shadelab.scene.model import (
    NORMALS_MODES,
    Object,
)
from shadelab.ui.panels import (
    combo,
    edit_fields,
    scene_span,
    vec3,
)
from shadelab.ui.ranges import field_slider

TESSELLATION_FIELDS = {"sphere": ("subdivisions", 0, 6), "quad": ("segments", 1, 64),
                       "plane": ("segments", 1, 64), "cylinder": ("sections", 3, 256),
                       "cone": ("sections", 3, 256), "torus": ("sections", 3, 256),
                       "capsule": ("sections", 3, 256)}


def draw_objects_panel(state: AppState) -> bool:
    """Normals mode and tessellation per object (geometry re-uploads for that object only)."""
    edited = False
    materials = tuple(state.scene.materials)
    for i, obj in enumerate(state.scene.objects):
        imgui.push_id(f"object{i}")
        if imgui.tree_node(f"{obj.name or obj.shape} ({obj.shape})###obj"):
            rows: list[tuple] = [("material", combo, materials),
                                 ("normals", combo, NORMALS_MODES)]
            if obj.normals == "crease":
                rows.append(("crease_angle", field_slider(Object)))
            edited |= edit_fields(obj, rows)
            edited |= draw_transform(obj, scene_span(state))
            if obj.shape in TESSELLATION_FIELDS:
                field, lo, hi = TESSELLATION_FIELDS[obj.shape]
                changed, value = imgui.slider_int(f"tessellation ({field})", getattr(obj, field),
                                                  lo, hi)
                if changed:
                    setattr(obj, field, value)
                    edited = True
            imgui.tree_pop()
        imgui.pop_id()
    return edited


MIN_SCALE = 1e-3  # a scale of 0 flattens the object into degenerate triangles


def draw_transform(obj: Object, span: float) -> bool:
    """Translate (world units), rotate (XYZ degrees) and scale of ``obj``: drag or Ctrl+click
    to type; each drag is one undo step (the viewer commits edits when the mouse lets go)."""
    imgui.separator_text("transform")
    edited = False
    changed, value = vec3("translate", obj.translate, max(span, 1e-6) * 0.002)
    if changed:
        obj.translate, edited = value, True
    changed, value = vec3("rotate (deg)", obj.rotate, 0.5)
    if changed:
        obj.rotate, edited = value, True
    changed, value = vec3("scale", obj.scale, 0.005)
    if changed:
        obj.scale = tuple(c if abs(c) >= MIN_SCALE else math.copysign(MIN_SCALE, c or 1.0)
                          for c in value)
        edited = True
    if imgui.small_button("reset transform"):
        obj.translate, obj.rotate, obj.scale = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (1.0, 1.0, 1.0)
        edited = True
    return edited
