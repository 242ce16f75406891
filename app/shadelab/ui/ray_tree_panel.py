"""The "Ray tree" dock window: the picked pixel's ray tree as the slide draws it, a 2D node
diagram (:mod:`shadelab.lab.ray_tree_layout`) drawn with imgui's draw list.

The tree is the ray-traced viewport's (a click in it picks the pixel), else the Offline render
panel's. The diagram is measured with the current font, which the presenter scale already
enlarges (ui/app.py sets ``font_scale_main``), and scaled down only when the window is too
narrow for it. Hovering a box highlights its ray in the ray-traced viewport's 3D overlay
(``PipelineView.tree_hover``, read by :func:`shadelab.ui.pipelines.draw_ray_tree`).
"""

from __future__ import annotations

from imgui_bundle import imgui

from shadelab.lab.pipeline_view import view_of
from shadelab.lab.ray_tree_layout import Diagram, layout
from shadelab.lab.state import AppState

#: Box borders and edge labels by ray kind (the 3D overlay's colours, ABGR)
KIND_COLORS = {"primary": 0xFFFFFFFF, "reflected": 0xFF30D0FF, "refracted": 0xFFFFB040,
               "shadow": 0xFF60E060}
BLOCKED = 0xFF4040FF
HOVER = 0xFF00FFFF
BOX_FILL = 0xE0302820
LABEL_FILL = 0xC0000000


def shown_tree(state: AppState):
    """(root, scene, pixel, where) of the tree the window shows: the ray-traced viewport's,
    else the Offline panel's; (None, None, None, "") when no pixel is picked."""
    view = state.view.pipeline_view
    if view is not None and view.ray_tree is not None and view.job_scene is not None:
        return view.ray_tree, view.job_scene, view.ray_tree_pixel, "viewport"
    offline = state.offline
    if offline.ray_tree is not None and offline.scene is not None:
        return offline.ray_tree, offline.scene, offline.ray_tree_pixel, "offline"
    return None, None, None, ""


def diagram_of(root, scene, pixel, width: float, measure=None, line_h: float = 14.0) -> Diagram:
    names = [o.name or o.shape for o in scene.objects]
    return layout(root, names, width, measure=measure, line_h=line_h, pixel=pixel)


def draw_ray_tree_panel(state: AppState) -> bool:
    root, scene, pixel, where = shown_tree(state)
    if root is None:
        imgui.text_wrapped("No ray tree: pick the Ray tracing pipeline and click a pixel of the "
                           "viewport (or click the Offline panel's Whitted image).")
        return False
    total = root.total()
    width = max(imgui.get_content_region_avail().x - 4.0, 120.0)
    font_size = imgui.get_font_size()
    diagram = diagram_of(root, scene, pixel, width, measure=lambda s: imgui.calc_text_size(s).x,
                         line_h=imgui.get_text_line_height())
    shrunk = f", text x{diagram.scale:.2f}: widen the window" if diagram.scale < 0.99 else ""
    imgui.text_wrapped(f"pixel {pixel} ({where}): {sum(1 for _ in root.flatten())} rays, "
                       f"value ({total[0]:.3f}, {total[1]:.3f}, {total[2]:.3f}) = sum of c"
                       + shrunk)
    origin = imgui.get_cursor_screen_pos()
    imgui.invisible_button("##ray_tree_canvas", imgui.ImVec2(width, max(diagram.height, 1.0)))
    hovered = None
    if imgui.is_item_hovered():
        mouse = imgui.get_mouse_pos()
        hovered = diagram.node_at(mouse.x - origin.x, mouse.y - origin.y)
    if where == "viewport":
        view_of(state).tree_hover = hovered.node if hovered is not None else None
    draw_diagram(imgui.get_window_draw_list(), origin, diagram, font_size * diagram.scale,
                 hovered)
    return False


def _color(n) -> int:
    if n.kind == "shadow" and n.node.shadow < 1.0:
        return BLOCKED
    return KIND_COLORS.get(n.kind, 0xFFFFFFFF)


def draw_diagram(draw_list, origin, diagram: Diagram, font_size: float, hovered=None) -> None:
    def at(x, y):
        return imgui.ImVec2(origin.x + x, origin.y + y)

    font = imgui.get_font()
    line_h = diagram.line_h

    def centred(box, text) -> float:  # the text's x, centred in its box
        return box.x + (box.w - imgui.calc_text_size(text).x * diagram.scale) / 2

    for (x0, y0), (x1, y1) in diagram.wires():
        draw_list.add_line(at(x0, y0), at(x1, y1), 0xFFA0A0A0, 1.5)
    for n in diagram.nodes:
        color = HOVER if n is hovered else _color(n)
        b, lb = n.box, n.label
        draw_list.add_rect_filled(at(lb.x, lb.y), at(lb.x + lb.w, lb.y + lb.h), LABEL_FILL)
        for k, text in enumerate(n.label_lines):
            draw_list.add_text(font, font_size, at(centred(lb, text), lb.y + k * line_h), color,
                               text)
        draw_list.add_rect_filled(at(b.x, b.y), at(b.x + b.w, b.y + b.h), BOX_FILL, 3.0)
        draw_list.add_rect(at(b.x, b.y), at(b.x + b.w, b.y + b.h), color, 3.0,
                           3.0 if n is hovered else 1.5)
        pad = (b.h - len(n.lines) * line_h) / 2
        for k, text in enumerate(n.lines):
            draw_list.add_text(font, font_size, at(centred(b, text), b.y + pad + k * line_h),
                               0xFFFFFFFF, text)
