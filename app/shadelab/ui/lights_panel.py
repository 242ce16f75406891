"""The Lights window: every light's kind, position, intensity and attenuation (with its
curve), add and remove (:func:`draw_lights_panel`)."""

from __future__ import annotations

import numpy as np
from imgui_bundle import imgui, implot

from shadelab.lab.state import AppState
from shadelab.scene.model import (
    ATTENUATION_MODES,
    LIGHT_KINDS,
    Light,
)
from shadelab.shading import reference
from shadelab.shading.lights import light_kind
from shadelab.ui.layout import plot_size
from shadelab.ui.panels import (
    combo,
    edit_fields,
    intensity_color,
    scene_span,
    vec3,
)
from shadelab.ui.ranges import field_slider

# ---------------------------------------------------------------- lights


def _light_rows(light: Light, span: float) -> list[tuple]:
    kind = light_kind(light)
    rows: list[tuple] = [("kind", combo, LIGHT_KINDS)]
    if not kind.at_infinity:
        rows.append(("position", vec3, span * 0.005))
    if kind.aimed:
        rows.append(("direction", vec3, 0.01))
    rows.append(("Ip", intensity_color))
    if kind.has_cone:
        rows += [("cone_angle", field_slider(Light)), ("spot_exponent", field_slider(Light))]
    if not kind.at_infinity:
        rows.append(("attenuation", combo, ATTENUATION_MODES))
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
            edited |= edit_fields(light, _light_rows(light, span))
            if not light_kind(light).at_infinity and light.attenuation != "none":
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
