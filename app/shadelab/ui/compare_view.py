"""The viewport's compare layout (the C key): flat, Gouraud, Phong and Blinn-Phong side by side
under one camera, or the difference heat map of two of them (GL side: draws the viewer's
panes)."""

from __future__ import annotations

from imgui_bundle import imgui

from shadelab.lab import camera_control
from shadelab.lab.state import COMPARE_LABELS, COMPARE_VIEWS, AppState
from shadelab.shading.codes import terms_mask
from shadelab.ui.viewport_host import ViewportHost


def draw_compare(viewer: ViewportHost, size: tuple[int, int]) -> None:
    """The 2x2 grid of shading modes under one camera, or the difference heat map of two of
    them with both as thumbnails (the D key)."""
    state, vp = viewer.state, viewer.viewport
    scene = state.scene
    # Four quadrants; with the heat map, the map takes 70% of the width at full height.
    if state.view.diff_enabled:
        half = (max(int(size[0] * 0.7), 8), max(size[1], 8))
    else:
        half = (max(size[0] // 2, 8), max(size[1] // 2, 8))
    exposure = scene.render.exposure
    if "compare3" in vp.panes and viewer.unchanged(size):
        panes = [vp.panes[f"compare{i}"] for i in range(len(COMPARE_VIEWS))]
    else:
        off = terms_mask(state.view.terms_off)   # the caption's switched-off terms
        panes = [vp.draw_scene(f"compare{i}", scene, half, shading, specular, viewer.samples(),
                               off)
                 for i, (shading, specular) in enumerate(COMPARE_VIEWS)]
    if state.view.diff_enabled:
        a, b = state.view.diff_pair
        diff = vp.pane("diff", half)
        vp.present(diff, exposure, panes[a], panes[b], state.view.diff_scale)
        origin = imgui.get_cursor_screen_pos()
        texture = diff.display
        viewer.image_with_input(texture, half)
        draw = imgui.get_window_draw_list()
        draw.add_text(imgui.ImVec2(origin.x + 6, origin.y + 4), 0xFFFFFFFF,
                      f"|{COMPARE_LABELS[a]} - {COMPARE_LABELS[b]}| x exposure, "
                      f"full red = {state.view.diff_scale:.3g}")
        imgui.same_line()
        imgui.begin_group()
        thumb_w = max(size[0] - half[0] - 12, 8)
        thumb_h = min(thumb_w * half[1] / half[0], size[1] / 2 - 30)
        for i in (a, b):
            tex = vp.present(panes[i], exposure)
            imgui.image(imgui.ImTextureRef(tex.glo),
                        imgui.ImVec2(thumb_h * half[0] / half[1], thumb_h),
                        uv0=imgui.ImVec2(0, 1), uv1=imgui.ImVec2(1, 0))
            imgui.text(COMPARE_LABELS[i])
        imgui.end_group()
        return
    origin = imgui.get_cursor_screen_pos()
    for pane in panes:
        vp.present(pane, exposure, tonemap=state.view.tonemap, clipping=state.view.show_clipping)
    draw = imgui.get_window_draw_list()
    for i, pane in enumerate(panes):
        x = origin.x + (i % 2) * half[0]
        y = origin.y + (i // 2) * half[1]
        imgui.set_cursor_screen_pos(imgui.ImVec2(x, y))
        imgui.image(imgui.ImTextureRef(pane.display.glo), imgui.ImVec2(*half),
                    uv0=imgui.ImVec2(0, 1), uv1=imgui.ImVec2(1, 0))
        draw.add_text(imgui.ImVec2(x + 6, y + 4), 0xFFFFFFFF, COMPARE_LABELS[i])
    # One input area over the grid drives the shared camera.
    imgui.set_cursor_screen_pos(origin)
    grid_input(state, (half[0] * 2, half[1] * 2), half[1])

def grid_input(state: AppState, size: tuple[int, int], pane_height: int) -> None:
    """One input area over the grid: orbit, pan and zoom the shared camera."""
    io = imgui.get_io()
    imgui.invisible_button("compare_input", imgui.ImVec2(*size),
                           imgui.ButtonFlags_.mouse_button_left
                           | imgui.ButtonFlags_.mouse_button_right)
    camera = state.scene.camera
    if imgui.is_item_active() and (io.mouse_delta.x or io.mouse_delta.y):
        camera_control.drag(camera, io.mouse_delta.x, io.mouse_delta.y,
                            imgui.is_mouse_down(imgui.MouseButton_.left), size[1], pane_height)
        state.mark_edited()
    if imgui.is_item_hovered() and io.mouse_wheel:
        camera_control.zoom(camera, io.mouse_wheel)
        state.mark_edited()
