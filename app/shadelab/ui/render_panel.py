"""Every algorithm's controls, live: the pipeline selector and wipe, raster shadows and
visibility, the ray tracer, the path tracer and radiosity, and the material extras.

Each control edits a field of the scene (undoable, autosaved, saved into the preset) or of the
job (``state.offline.spp``); slider ranges come from the field's spec in
:mod:`shadelab.scene.model`. A typed value outside the spec is refused in place: the field
shows the reason underneath and the scene keeps its value.
"""

from __future__ import annotations

import math
from dataclasses import fields

from imgui_bundle import imgui

from shadelab.lab.state import AppState
from shadelab.scene.model import (
    RADIOSITY_SOLVERS,
    TRANSPARENCY_MODELS,
    Material,
    RaytraceSettings,
)
from shadelab.ui import pipelines
from shadelab.ui.layout import plot_size

ERROR_COLOR = imgui.ImVec4(1.0, 0.35, 0.3, 1.0)
DIM_COLOR = imgui.ImVec4(0.65, 0.65, 0.65, 1.0)
_refused: dict[str, str] = {}   # widget id -> the last refusal, shown under the field


def field_spec(cls, name: str) -> tuple:
    """The (kind, *args) validation spec of a model field."""
    for f in fields(cls):
        if f.name == name:
            return f.metadata["spec"]
    raise KeyError(name)


def _show_refusal(key: str) -> None:
    if key in _refused:
        imgui.push_text_wrap_pos(0.0)
        imgui.text_colored(ERROR_COLOR, _refused[key])
        imgui.pop_text_wrap_pos()


def int_field(label: str, obj, name: str, lo: int | None = None, hi: int | None = None,
              key: str = "") -> bool:
    """A typed integer (Enter applies); outside [lo, hi] (the spec's range by default) it is
    refused with a message and the field keeps its value."""
    kind, spec_lo, spec_hi = field_spec(type(obj), name)
    lo = spec_lo if lo is None else lo
    hi = spec_hi if hi is None else hi
    key = key or f"{type(obj).__name__}.{name}"
    changed, value = imgui.input_int(label, int(getattr(obj, name)), 1, 10,
                                     imgui.InputTextFlags_.enter_returns_true)
    edited = False
    if changed:
        if lo <= value <= hi:
            setattr(obj, name, int(value))
            _refused.pop(key, None)
            edited = True
        else:
            _refused[key] = f"{label} {value} refused: expected {lo} to {hi} (kept " \
                            f"{getattr(obj, name)})"
    _show_refusal(key)
    return edited


def float_slider(label: str, obj, name: str, lo: float | None = None, hi: float | None = None,
                 log: bool = False, fmt: str = "%.4g") -> bool:
    """A slider over the spec's range (or a narrower teaching range); Ctrl+click typing is
    clamped to the spec's range."""
    _, spec_lo, spec_hi = field_spec(type(obj), name)
    if lo is None or hi is None:
        from shadelab.ui.ranges import slider_range

        soft_lo, soft_hi, soft_log, fmt = slider_range(type(obj), name,
                                                       float(getattr(obj, name)))
        lo, hi, log = soft_lo if lo is None else lo, soft_hi if hi is None else hi, \
            log or soft_log
    flags = imgui.SliderFlags_.always_clamp | (imgui.SliderFlags_.logarithmic if log else 0)
    old = float(getattr(obj, name))
    changed, value = imgui.slider_float(label, old, lo, hi, fmt, flags)
    if changed and not math.isfinite(value):  # typed nan, inf or 1e309: the value is kept
        changed = False
    if changed:
        setattr(obj, name, float(min(max(value, spec_lo), spec_hi)))
    return changed


def combo(label: str, obj, name: str, choices, labels=None) -> bool:
    value = getattr(obj, name)
    index = choices.index(value) if value in choices else 0
    changed, index = imgui.combo(label, index, list(labels or choices))
    if changed:
        setattr(obj, name, choices[index])
    return changed


def checkbox(label: str, obj, name: str) -> bool:
    changed, value = imgui.checkbox(label, bool(getattr(obj, name)))
    if changed:
        setattr(obj, name, value)
    return changed


# ---------------------------------------------------------------- pipeline selector


def draw_pipeline_selector(state: AppState) -> bool:
    """"Pipeline" beside the shading modes, and the wipe comparing two pipelines."""
    now = pipelines.current(state)
    labels = [pipelines.LABELS[p] for p in pipelines.PIPELINES]
    changed, index = imgui.combo("Pipeline", pipelines.PIPELINES.index(now), labels)
    if changed:
        pipelines.set_pipeline(state, pipelines.PIPELINES[index])
    _, state.view.wipe = imgui.checkbox("Wipe: compare with", state.view.wipe)
    if state.view.wipe:
        imgui.same_line()
        imgui.set_next_item_width(180)
        other = state.view.wipe_pipeline
        other = other if other in pipelines.PIPELINES else "raytrace"
        changed, j = imgui.combo("##wipe_with", pipelines.PIPELINES.index(other), labels)
        if changed:
            state.view.wipe_pipeline = pipelines.PIPELINES[j]
        _, state.view.wipe_position = imgui.slider_float("wipe position",
                                                         state.view.wipe_position, 0.0, 1.0,
                                                         "%.2f")
        if state.view.wipe_pipeline in pipelines.OFFLINE and now in pipelines.OFFLINE \
                and state.view.wipe_pipeline != now:
            imgui.text_colored(DIM_COLOR, "one offline pipeline at a time: the right side "
                                          "waits")
    return False   # the raster choice marks its own edit (set_pipeline)


# ---------------------------------------------------------------- the panel


def draw_algorithms_panel(state: AppState) -> bool:
    """Raster, ray tracer, path tracer and radiosity settings (every one live)."""
    scene, edited = state.scene, False
    draw_pipeline_selector(state)
    imgui.separator()
    if imgui.collapsing_header("Raster: shadows and visibility",
                               imgui.TreeNodeFlags_.default_open):
        edited |= draw_raster_controls(state)
    if imgui.collapsing_header("Ray tracer (Whitted)", imgui.TreeNodeFlags_.default_open):
        r = scene.raytrace
        edited |= int_field("depth", r, "depth")
        edited |= int_field("spp (anti-aliasing)", r, "spp")
        edited |= checkbox("Fresnel (reflect/refract by F, 1 - F)", r, "fresnel")
        edited |= float_slider("ray offset", r, "offset", 1e-7, 0.1, log=True)
        edited |= float_slider("min weight", r, "min_weight", 0.0, 0.5)
    if imgui.collapsing_header("Path tracer", imgui.TreeNodeFlags_.default_open):
        changed, spp = imgui.input_int("path spp", int(state.offline.spp), 1, 16,
                                       imgui.InputTextFlags_.enter_returns_true)
        _, lo, hi = field_spec(RaytraceSettings, "spp")
        if changed:
            if lo <= spp <= hi:
                state.offline.spp = int(spp)
                _refused.pop("path_spp", None)
            else:
                _refused["path_spp"] = f"path spp {spp} refused: expected {lo} to {hi} " \
                                       f"(kept {state.offline.spp})"
        _show_refusal("path_spp")
    if imgui.collapsing_header("Radiosity", imgui.TreeNodeFlags_.default_open):
        edited |= draw_radiosity_controls(state)
    draw_pipeline_figures(state)
    return edited


def draw_pipeline_figures(state: AppState) -> None:
    """The running pipeline's figures: the radiosity residual curve, the picked ray tree."""
    view = state.view.pipeline_view
    if view is None:
        return
    name = pipelines.current(state)
    if name == "radiosity":
        from shadelab.ui.radiosity_view import draw_radiosity_stepper

        draw_radiosity_stepper(view)
    if name == "radiosity" and view.history.get("iteration"):
        _draw_residual_plot(view)
    if name == "raytrace":
        if view.ray_tree is None:
            imgui.text_colored(DIM_COLOR, "click a pixel of the ray-traced viewport: its ray "
                                          "tree is drawn there")
            return
        draw_ray_tree_table(state, view)


def _draw_residual_plot(view) -> None:
    from imgui_bundle import implot

    from shadelab.ui.radiosity_view import convergence_series

    x, y, label = convergence_series(view.history)
    if implot.begin_plot("radiosity convergence", plot_size(11.0)):
        implot.setup_axes("shots" if "unshot" in label else "iterations", label,
                          implot.AxisFlags_.auto_fit, implot.AxisFlags_.auto_fit)
        implot.setup_axis_scale(implot.ImAxis_.y1, implot.Scale_.log10)
        if x is not None and len(x):
            implot.plot_line(label, x, y)
        implot.end_plot()
    shooter = view.stats.get("shooter_index")
    imgui.text_wrapped(f"{view.stats.get('patches', 0)} patches, {view.stats.get('shots', 0)} shots"
               + (f", shooting patch {shooter}" if shooter is not None else "")
               + (", form factors reused" if view.stats.get("form_factors_reused") else ""))


def draw_ray_tree_table(state: AppState, view) -> None:
    root = view.ray_tree
    deepest = max(node.depth for _, node in root.flatten())
    imgui.text_wrapped(f"ray tree of pixel {view.ray_tree_pixel}: {sum(1 for _ in root.flatten())} "
               f"rays, depth {deepest}")
    shown = min(view.tree_depth, deepest)
    changed, shown = imgui.slider_int("show generations up to", shown, 0, max(deepest, 0))
    if changed:
        view.tree_depth = shown
    if imgui.small_button("Clear ray tree"):
        view.ray_tree = None
        return
    flags = imgui.TableFlags_.borders | imgui.TableFlags_.row_bg | imgui.TableFlags_.scroll_y
    if imgui.begin_table("pipeline_raytree", 3, flags, imgui.ImVec2(0, 180)):
        for head in ("ray", "hit (material)", "contribution"):
            imgui.table_setup_column(head)
        imgui.table_headers_row()
        for depth, node in root.flatten():
            if node.depth > view.tree_depth:
                continue
            imgui.table_next_row()
            imgui.table_next_column()
            label = node.kind + (f" to light {node.light}: S={node.shadow:g}"
                                 if node.kind == "shadow" else f" d{node.depth}")
            imgui.text_wrapped("  " * depth + label)
            imgui.table_next_column()
            imgui.text_wrapped("miss" if node.end is None
                       else pipelines.object_label(view.job_scene, node.object))
            imgui.table_next_column()
            imgui.text_wrapped(", ".join(f"{float(c):.3g}" for c in node.contribution))
        imgui.end_table()


def draw_raster_controls(state: AppState) -> bool:
    render, edited = state.scene.render, False
    edited |= combo("shadows", render, "shadows", ("none", "volumes"),
                    ("none", "shadow volumes"))
    imgui.begin_disabled(render.shadows != "volumes")
    edited |= combo("stencil counting", render, "shadow_method", ("zfail", "zpass"),
                    ("z-fail (Carmack)", "z-pass"))
    edited |= checkbox("show volumes", render, "show_volumes")
    imgui.same_line()
    edited |= checkbox("show silhouettes", render, "show_silhouettes")
    edited |= checkbox("stencil heat map", render, "stencil_heatmap")
    lights = state.scene.lights
    if render.stencil_heatmap and lights:
        names = [light.name or f"light {i}" for i, light in enumerate(lights)]
        index = min(render.heatmap_light, len(lights) - 1)
        changed, index = imgui.combo("heat map light", index, names)
        if changed:
            render.heatmap_light, edited = index, True
    imgui.end_disabled()
    edited |= combo("visibility", render, "visibility", ("zbuffer", "painter"),
                    ("z-buffer", "painter's (list priority)"))
    return edited


def draw_radiosity_controls(state: AppState) -> bool:
    r, edited = state.scene.radiosity, False
    edited |= int_field("patches", r, "patches", 1, 20000)
    edited |= combo("form factors", r, "form_factors", ("hemicube", "raycast", "analytic"))
    if r.form_factors == "hemicube":
        edited |= int_field("hemicube resolution", r, "hemicube_resolution")
    edited |= combo("solver", r, "solver", RADIOSITY_SOLVERS)
    edited |= int_field("iterations", r, "iterations")
    edited |= float_slider("tolerance", r, "tolerance", 1e-7, 0.1, log=True, fmt="%.2g")
    _, state.view.radiosity_patches = imgui.checkbox("draw patches (radiosity pipeline)",
                                                     state.view.radiosity_patches)
    edited |= checkbox("ambient estimate (progressive)", r, "ambient")
    return edited


# ---------------------------------------------------------------- material extras


TEXTURES = ("", "checker")
BUMPS = ("", "bumps")


def draw_material_extras(material: Material) -> bool:
    """Transparency model, kt, Ot, kr (following ks), ior, texture and bump strength."""
    edited = combo("transparency", material, "transparency", TRANSPARENCY_MODELS,
                   ("interpolated (1-kt) I1 + kt I2", "filtered I1 + kt Ot I2"))
    edited |= float_slider("kt", material, "kt")
    changed, ot = imgui.color_edit3("Ot", list(material.Ot), imgui.ColorEditFlags_.float)
    if changed:
        material.Ot, edited = tuple(min(max(float(c), 0.0), 1.0) for c in ot), True
    follows = material.kr < 0.0
    changed, follows = imgui.checkbox("kr = ks", follows)
    if changed:
        material.kr, edited = (-1.0 if follows else float(material.ks)), True
    imgui.same_line()
    if material.kr < 0.0:
        imgui.text_colored(DIM_COLOR, f"kr = ks = {material.ks:.3g}")
    else:
        imgui.set_next_item_width(160)
        edited |= float_slider("kr", material, "kr", 0.0, 1.0)
    edited |= float_slider("ior", material, "ior")
    texture = material.texture if material.texture in TEXTURES else "(image)"
    choices = TEXTURES + (("(image)",) if texture == "(image)" else ())
    labels = ["none", "checker"] + ([material.texture] if texture == "(image)" else [])
    changed, index = imgui.combo("texture", choices.index(texture), labels)
    if changed and choices[index] != "(image)":
        material.texture, edited = choices[index], True
    if material.texture:
        edited |= float_slider("texture scale", material, "texture_scale", 0.5, 64.0, log=True)
    bump = material.bump if material.bump in BUMPS else "(image)"
    choices = BUMPS + (("(image)",) if bump == "(image)" else ())
    labels = ["none", "bumps"] + ([material.bump] if bump == "(image)" else [])
    changed, index = imgui.combo("bump map", choices.index(bump), labels)
    if changed and choices[index] != "(image)":
        material.bump, edited = choices[index], True
    if material.bump:
        edited |= float_slider("bump strength", material, "bump_scale", 0.0, 10.0)
    return edited

