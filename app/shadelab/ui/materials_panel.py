"""The Materials window: every material's coefficients (:func:`draw_materials_panel`)."""

from __future__ import annotations

from imgui_bundle import imgui

from shadelab.lab.state import AppState
from shadelab.scene.model import (
    Material,
)
from shadelab.ui.panels import (
    edit_fields,
    intensity_color,
    rgb_color,
)
from shadelab.ui.ranges import field_slider

# ---------------------------------------------------------------- materials and objects


_M = field_slider(Material)  # ranges from the model's field table (shadelab.ui.ranges)
MATERIAL_ROWS = [("ka", _M), ("kd", _M), ("ks", _M), ("n", _M), ("Od", rgb_color),
                 ("Os", rgb_color)]
MATERIAL_MORE_ROWS = [("emission", intensity_color)]  # kt, Ot, kr, ior, texture, bump:
#                                    shadelab.ui.render_panel.draw_material_extras


def draw_materials_panel(state: AppState) -> bool:
    """The lecture's coefficients per material (ray-tracer and radiosity ones folded)."""
    edited = False
    for i, (name, material) in enumerate(state.scene.materials.items()):
        imgui.push_id(f"material_{name}")
        if imgui.tree_node_ex(name, imgui.TreeNodeFlags_.default_open if i == 0 else 0):
            edited |= edit_fields(material, MATERIAL_ROWS)
            if imgui.tree_node("transparency, reflection, emission"):
                from shadelab.ui.render_panel import draw_material_extras

                edited |= draw_material_extras(material)
                edited |= edit_fields(material, MATERIAL_MORE_ROWS)
                imgui.tree_pop()
            imgui.tree_pop()
        imgui.pop_id()
    return edited
