"""The viewer's panels: each ``draw_<x>_panel(state) -> bool`` (True when it edited the scene).

Panels only read and write :class:`shadelab.lab.state.AppState`; GL work is asked for through it
(``state.probe.requested``, ``state.screenshot_requested``) and done by :mod:`shadelab.ui.app`.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from imgui_bundle import imgui, implot

from shadelab.lab.state import COMPARE_LABELS, AppState
from shadelab.scene.model import (
    ATTENUATION_MODES,
    LIGHT_KINDS,
    NORMALS_MODES,
    SHADING_MODES,
    SPECULAR_MODELS,
    Light,
    Material,
    Object,
    RenderSettings,
)
from shadelab.scene.preset import list_presets
from shadelab.shading import reference
from shadelab.ui import dialogs
from shadelab.ui.layout import plot_size, same_line_if_fits
from shadelab.ui.ranges import field_slider, intensity_range

ERROR_COLOR = imgui.ImVec4(1.0, 0.35, 0.3, 1.0)
DIM_COLOR = imgui.ImVec4(0.65, 0.65, 0.65, 1.0)
OK_COLOR = imgui.ImVec4(0.4, 0.9, 0.4, 1.0)
SHADING_LABELS = {"flat": "Flat", "gouraud": "Gouraud", "phong": "Phong"}
SPECULAR_LABELS = {"phong": "Phong (R.V)^n", "blinn": "Blinn-Phong (N.H)^n"}
TESSELLATION_FIELDS = {"sphere": ("subdivisions", 0, 6), "quad": ("segments", 1, 64),
                       "plane": ("segments", 1, 64), "cylinder": ("sections", 3, 256),
                       "cone": ("sections", 3, 256), "torus": ("sections", 3, 256),
                       "capsule": ("sections", 3, 256)}


# ---------------------------------------------------------------- small widgets


def _combo(label: str, value: str, choices: tuple[str, ...]) -> tuple[bool, str]:
    changed, index = imgui.combo(label, choices.index(value), list(choices))
    return changed, choices[index]


def _color(label: str, value) -> tuple[bool, tuple[float, float, float]]:
    changed, rgb = imgui.color_edit3(label, list(value), imgui.ColorEditFlags_.float)
    return changed, tuple(float(c) for c in rgb)


def _intensity_color(label: str, value) -> tuple[bool, tuple[float, float, float]]:
    """An RGB of any size as a color (max channel 1) times an intensity (log slider)."""
    rgb = np.asarray(value, dtype=np.float64)
    scale = float(rgb.max())
    color = rgb / scale if scale > 0 else np.ones(3)
    imgui.push_id(label)
    changed_c, color = _color(f"{label} color", tuple(color))
    changed_s, scale = imgui.slider_float(f"{label} intensity", scale, 0.0,
                                          intensity_range(scale), "%.4g")
    imgui.pop_id()
    if changed_c or changed_s:
        return True, tuple(float(c) * scale for c in color)
    return False, tuple(value)


def _slider(label: str, value: float, lo: float, hi: float, log: bool = False,
            fmt: str = "%.3f") -> tuple[bool, float]:
    flags = imgui.SliderFlags_.logarithmic if log else 0
    return imgui.slider_float(label, float(value), lo, hi, fmt, flags)


def _vec3(label: str, value, speed: float) -> tuple[bool, tuple[float, float, float]]:
    changed, v = imgui.drag_float3(label, list(value), speed, 0.0, 0.0, "%.3g")
    return changed, tuple(float(c) for c in v)


def _edit_fields(obj, rows: list[tuple]) -> bool:
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
    edited |= _edit_fields(scene.render, [("exposure", field_slider(RenderSettings))])
    edited |= _edit_fields(scene, [("Ia", _intensity_color)])
    _, state.view.show_wireframe = imgui.checkbox("Wireframe (W)", state.view.show_wireframe)
    imgui.same_line()
    _, state.view.show_normals = imgui.checkbox("Normals (N)", state.view.show_normals)
    if state.view.show_normals:
        _, state.view.normal_length = _slider("glyph length", state.view.normal_length,
                                              0.005, 0.3, True)
    changed, mode = _combo("normals (all)", "", ("",) + NORMALS_MODES)
    if changed and mode:
        for obj in scene.objects:
            obj.normals = mode
        edited = True
    return edited


# ---------------------------------------------------------------- lights


def _light_rows(light: Light, span: float) -> list[tuple]:
    rows: list[tuple] = [("kind", _combo, LIGHT_KINDS)]
    if light.kind in ("point", "spot"):
        rows.append(("position", _vec3, span * 0.005))
    if light.kind in ("directional", "spot"):
        rows.append(("direction", _vec3, 0.01))
    rows.append(("Ip", _intensity_color))
    if light.kind == "spot":
        rows += [("cone_angle", field_slider(Light)), ("spot_exponent", field_slider(Light))]
    if light.kind != "directional":
        rows.append(("attenuation", _combo, ATTENUATION_MODES))
        if light.attenuation == "lecture":
            rows += [(c, field_slider(Light)) for c in ("c1", "c2", "c3")]
    return rows


def attenuation_curve(state: AppState, light: Light, samples: int = 200):
    """f_att over the distances from the light to the scene's surfaces (vertex distances)."""
    from shadelab.geometry.mesh import scene_meshes

    points = np.concatenate([m.vertices for m in scene_meshes(state.scene)])
    distances = np.linalg.norm(points - np.asarray(light.position), axis=1)
    far = float(distances.max()) if len(distances) else 1.0
    near = max(float(distances.min()) if len(distances) else 0.0, 0.02 * far)
    d = np.linspace(near, far, samples)
    f = reference.attenuation(d, light.attenuation, light.c1, light.c2, light.c3)
    return d, np.asarray(f, dtype=np.float64)


def _draw_attenuation_plot(state: AppState, index: int, light: Light) -> None:
    d, f = attenuation_curve(state, light)
    if implot.begin_plot(f"f_att(d)##{index}", plot_size(9.5),
                          implot.Flags_.no_legend):
        implot.setup_axes("d (scene units)", "f_att",
                          implot.AxisFlags_.auto_fit, implot.AxisFlags_.auto_fit)
        if light.attenuation == "inverse_square":
            implot.setup_axis_scale(implot.ImAxis_.y1, implot.Scale_.log10)
        implot.plot_line("f_att", d, f)
        probe = state.probe.result
        active = [i for i, other in enumerate(state.scene.lights) if other.enabled]
        if probe is not None and index in active \
                and active.index(index) < len(probe.terms.lights):
            term = probe.terms.lights[active.index(index)]
            implot.plot_inf_lines("probe d", np.array([float(term.distance)]))
        implot.end_plot()


def draw_lights_panel(state: AppState) -> bool:
    """Every light: kind, placement, Ip, cone, attenuation with its f_att(d) curve."""
    scene, edited, span = state.scene, False, scene_span(state)
    from shadelab.ui.gizmos import draw_selector

    draw_selector(state)  # which light the viewport's gizmo drags
    remove = None
    for i, light in enumerate(scene.lights):
        imgui.push_id(f"light{i}")
        label = light.name or f"light {i}"
        changed, light.enabled = imgui.checkbox("##on", light.enabled)
        edited |= changed
        imgui.same_line()
        if imgui.tree_node_ex(f"{label} ({light.kind})###node",
                              imgui.TreeNodeFlags_.default_open if i == 0 else 0):
            edited |= _edit_fields(light, _light_rows(light, span))
            if light.kind != "directional" and light.attenuation != "none":
                _draw_attenuation_plot(state, i, light)
            if imgui.small_button("Remove light"):
                remove = i
            imgui.tree_pop()
        imgui.pop_id()
    if remove is not None:
        scene.lights.pop(remove)
        edited = True
    if imgui.button("Add light"):
        scene.lights.append(_new_light(state))
        edited = True
    return edited


def _new_light(state: AppState) -> Light:
    """A white point light above the camera target, about as bright as the first one."""
    cam = state.scene.camera
    span = scene_span(state)
    position = tuple(float(c) for c in np.add(cam.target, (0.0, 0.5 * span, -0.3 * span)))
    existing = state.scene.lights[0] if state.scene.lights else None
    if existing is not None and existing.attenuation == "inverse_square":
        ip = (float(max(existing.Ip)),) * 3
        return Light(kind="point", name=f"light {len(state.scene.lights)}", position=position,
                     Ip=ip, attenuation="inverse_square")
    return Light(kind="point", name=f"light {len(state.scene.lights)}", position=position)


# ---------------------------------------------------------------- materials and objects


_M = field_slider(Material)  # ranges from the model's field table (shadelab.ui.ranges)
MATERIAL_ROWS = [("ka", _M), ("kd", _M), ("ks", _M), ("n", _M), ("Od", _color), ("Os", _color)]
MATERIAL_MORE_ROWS = [("emission", _intensity_color)]  # kt, Ot, kr, ior, texture, bump:
#                                    shadelab.ui.render_panel.draw_material_extras


def draw_materials_panel(state: AppState) -> bool:
    """The lecture's coefficients per material (ray-tracer and radiosity ones folded)."""
    edited = False
    for i, (name, material) in enumerate(state.scene.materials.items()):
        imgui.push_id(f"material_{name}")
        if imgui.tree_node_ex(name, imgui.TreeNodeFlags_.default_open if i == 0 else 0):
            edited |= _edit_fields(material, MATERIAL_ROWS)
            if imgui.tree_node("transparency, reflection, emission"):
                from shadelab.ui.render_panel import draw_material_extras

                edited |= draw_material_extras(material)
                edited |= _edit_fields(material, MATERIAL_MORE_ROWS)
                imgui.tree_pop()
            imgui.tree_pop()
        imgui.pop_id()
    return edited


def draw_objects_panel(state: AppState) -> bool:
    """Normals mode and tessellation per object (geometry re-uploads for that object only)."""
    edited = False
    materials = tuple(state.scene.materials)
    for i, obj in enumerate(state.scene.objects):
        imgui.push_id(f"object{i}")
        if imgui.tree_node(f"{obj.name or obj.shape} ({obj.shape})###obj"):
            rows: list[tuple] = [("material", _combo, materials),
                                 ("normals", _combo, NORMALS_MODES)]
            if obj.normals == "crease":
                rows.append(("crease_angle", field_slider(Object)))
            edited |= _edit_fields(obj, rows)
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
    changed, value = _vec3("translate", obj.translate, max(span, 1e-6) * 0.002)
    if changed:
        obj.translate, edited = value, True
    changed, value = _vec3("rotate (deg)", obj.rotate, 0.5)
    if changed:
        obj.rotate, edited = value, True
    changed, value = _vec3("scale", obj.scale, 0.005)
    if changed:
        obj.scale = tuple(c if abs(c) >= MIN_SCALE else math.copysign(MIN_SCALE, c or 1.0)
                          for c in value)
        edited = True
    if imgui.small_button("reset transform"):
        obj.translate, obj.rotate, obj.scale = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (1.0, 1.0, 1.0)
        edited = True
    return edited


# ---------------------------------------------------------------- equation and probe


EQUATION = "I = Le + Ia ka Od + sum_i S_i f_att,i Ip,i [kd Od (N.L_i) + ks Os (R_i.V)^n]"
EQUATION_BLINN = "I = Le + Ia ka Od + sum_i S_i f_att,i Ip,i [kd Od (N.L_i) + ks Os (N.H_i)^n]"


def _rgb(v, digits: int = 3) -> str:
    """A 3-vector for reading: components below 1e-9 of its largest show as 0 (a unit normal
    reads (0, 0, 1), not (3.49e-17, -4.5e-16, 1))."""
    c = np.asarray(v, dtype=np.float64).reshape(-1)[:3]
    tiny = 1e-9 * max(float(np.abs(c).max()) if c.size else 0.0, 1e-300)
    return "(" + ", ".join(f"{0.0 if abs(x) < tiny else float(x):.{digits}g}" for x in c) + ")"


def _term_row(label: str, value) -> None:
    imgui.table_next_row()
    imgui.table_next_column()
    imgui.text_wrapped(label)
    values = np.asarray(value, dtype=np.float64).reshape(-1)
    for c in range(3):
        imgui.table_next_column()
        if c < len(values):
            v = values[c]  # tiny values short (e.g. 4.0e-66) so narrow columns show them
            imgui.text(f"{v:.4g}" if v == 0 or abs(v) >= 1e-3 else f"{v:.1e}")


def draw_equation_panel(state: AppState) -> bool:
    """The lecture's equation with the current numbers, and the probed pixel's terms."""
    scene = state.scene
    blinn = scene.render.specular == "blinn"
    imgui.text_wrapped(EQUATION_BLINN if blinn else EQUATION)
    imgui.text_wrapped("f_att = min(1 / (c1 + c2 d + c3 d^2), 1);  "
                       + ("H = (L + V) / |L + V|" if blinn else "R = 2 N (N.L) - L"))
    imgui.text_wrapped(f"Ia = {_rgb(scene.Ia)}   shading: {SHADING_LABELS[scene.render.shading]}")
    result = state.probe.result
    if result is None:
        imgui.separator()
        imgui.text_wrapped("Click a pixel in the viewport to probe it: its N, L_i, V and "
                           + ("H_i" if blinn else "R_i") + " are drawn as arrows and every "
                           "term is listed here.")
        return False
    m = scene.materials[result.hit.mesh.material]
    imgui.separator()
    imgui.text_wrapped(f"pixel {result.pixel}  object {result.hit.mesh.index} "
               f"({scene.objects[result.hit.mesh.index].name or 'unnamed'}), material "
               f"'{result.hit.mesh.material}'")
    imgui.text_wrapped(f"P = {_rgb(result.point, 4)}  N = {_rgb(result.normal)}")
    imgui.text_wrapped(f"V = {_rgb(result.to_eye)}")
    imgui.text_wrapped(f"ka {m.ka:.3g}  kd {m.kd:.3g}  ks {m.ks:.3g}  n {m.n:.3g}  "
               f"Od {_rgb(m.Od)}  Os {_rgb(m.Os)}")
    imgui.push_text_wrap_pos(0.0)
    imgui.text_colored(DIM_COLOR, "arrows: N white, V cyan, L_i yellow, "
                       + ("H_i" if blinn else "R_i") + " magenta")
    imgui.pop_text_wrap_pos()
    lights = scene.active_lights()
    # Stretched to the panel's width (the term column wider): every column stays on screen
    # in a narrow presenter layout (1024x768), where fixed-fit columns pushed B off the edge.
    flags = (imgui.TableFlags_.borders | imgui.TableFlags_.row_bg
             | imgui.TableFlags_.sizing_stretch_prop)
    if imgui.begin_table("terms", 4, flags):
        for head, weight in (("term", 1.8), ("R", 1.0), ("G", 1.0), ("B", 1.0)):
            imgui.table_setup_column(head, imgui.TableColumnFlags_.width_stretch, weight)
        imgui.table_headers_row()
        terms = result.terms
        _term_row("Le (emission)", terms.emission)
        _term_row("ambient Ia ka Od", terms.ambient)
        for i, t in enumerate(terms.lights[:len(lights)]):
            name = lights[i].name or f"light {i}"
            n_dot_l = float(np.dot(result.normal, t.to_light))
            spec_cos = float(np.dot(result.normal if blinn else result.reflected(i),
                                    result.reflected(i) if blinn else result.to_eye))
            _term_row(f"{name}: d, f_att", (float(t.distance), float(t.f_att)))
            shadow = np.asarray(t.shadow, dtype=np.float64).reshape(-1)
            if np.ptp(shadow) > 0.0:     # kt-filtered: one S_i per channel
                _term_row(f"{name}: S_i (r, g, b)", shadow)
                _term_row(f"{name}: spot", float(t.spot))
            else:
                _term_row(f"{name}: S_i, spot", (float(shadow[0]), float(t.spot)))
            _term_row(f"{name}: N.L, {'N.H' if blinn else 'R.V'}", (n_dot_l, spec_cos))
            _term_row(f"{name}: diffuse", t.diffuse)
            _term_row(f"{name}: specular", t.specular)
        if result.shading != "phong":
            _term_row("sum at this point", terms.total)
        _term_row(f"I ({result.shading} reference)", result.reference)
        if result.gpu is not None:
            _term_row("GPU drew", result.gpu)
        imgui.end_table()
    for i, t in enumerate(result.terms.lights[:len(lights)]):
        name = lights[i].name or f"light {i}"
        if lights[i].attenuation == "lecture":
            imgui.text_wrapped(f"{name}: min(1/(c1 + c2 d + c3 d^2), 1) clamp "
                       + ("ACTIVE (f_att = 1)" if bool(t.clamp_active) else "not active"))
        else:
            imgui.text_wrapped(f"{name}: attenuation '{lights[i].attenuation}' "
                               "(no min(., 1) clamp)")
    if result.gpu is not None:
        err = float(np.max(np.abs(result.gpu - result.reference)))
        agree = err <= 1e-4 * max(1.0, float(np.max(np.abs(result.reference))))
        imgui.push_text_wrap_pos(0.0)
        imgui.text_colored(OK_COLOR if agree else ERROR_COLOR,
                           f"GPU vs numpy reference: max |diff| {err:.2g} "
                           + ("(agree)" if agree else "(DIFFER)"))
        imgui.pop_text_wrap_pos()
    if result.shading != "phong":
        imgui.text_wrapped(f"{SHADING_LABELS[result.shading]} shading: the terms above are at "
                           "the probed point; the pixel's I is "
                           + ("the centroid's value." if result.shading == "flat"
                              else "the corners' values blended by barycentrics."))
    return False


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
    _, state.view.diff_scale = _slider("full scale |A-B|", state.view.diff_scale, 1e-4, 1.0,
                                       True, "%.4g")
    return False

