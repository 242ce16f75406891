"""The main viewport in a pipeline of :mod:`shadelab.ui.pipelines` (GL side, GL thread).

The Viewer calls :func:`draw` for the viewport window: the offline pipelines' latest image
(uploaded by :func:`shadelab.ui.pipelines.poll` through ``state.gpu``), the radiosity
triangles under the live camera, a raster pipeline's own pane, and the wipe between two.
"""

from __future__ import annotations

import time

import numpy as np
from imgui_bundle import imgui

from shadelab.scene.preset import clone_scene
from shadelab.ui import presenter
from shadelab.ui.pipelines import (
    LABELS,
    OFFLINE,
    PIPELINES,
    RASTER,
    SHOOTER_ABGR,
    SHOOTER_HALO,
    current,
    draw_ray_tree,
    label,
    patch_edges,
    pick_ray_tree,
    poll,
    prefetch_tick,
    project,
    shooter_outline,
    status_line,
    sync,
    track_side_panel_job,
    view_of,
)
from shadelab.ui.radiosity_view import viewport_soup
from shadelab.ui.viewport_host import ViewportHost


def draw(viewer: ViewportHost, display_size: tuple[int, int]) -> bool:
    """The main viewport in an offline pipeline or with the wipe; False: the raster path."""
    state = viewer.state
    view = view_of(state)
    sync(state)
    track_side_panel_job(state)
    name = current(state)
    wipe = (state.view.wipe and state.view.wipe_pipeline in PIPELINES
            and state.view.wipe_pipeline != name)
    scale = state.view.render_scale
    size = (max(int(display_size[0] * scale), 8), max(int(display_size[1] * scale), 8))
    ahead = state.walk.next_size or display_size     # the next lesson step's viewport
    next_size = (max(int(ahead[0] * scale), 8), max(int(ahead[1] * scale), 8))
    if name not in OFFLINE and not wipe:
        if state.frame >= 3:    # the next lesson step's offline job, ahead of time
            prefetch_tick(state, next_size)
        if view.runner is not None and view.runner.running and view.name in OFFLINE:
            view.runner.cancel()
        view.key = None
        return False
    if state.frame < 3:     # the dock layout settles over the first frames: no job at 16x16
        return True
    other = state.view.wipe_pipeline if wipe else None
    offline = [n for n in (name, other) if n in OFFLINE]
    if offline:
        poll(state, offline[0], size)      # (adopts a prefetched job first: then the tick)
        prefetch_tick(state, next_size)
        viewer.gpu.flush_uploads(state.gpu)  # a new image: on its texture this frame
        if view.runner.running:
            view.frame_times.append(time.perf_counter())
    elif view.runner is not None and view.runner.running and view.name in OFFLINE:
        view.runner.cancel()
        view.key = None
    tex_a = _texture(viewer, name, size, offline)
    origin = imgui.get_cursor_screen_pos()
    clicked = viewer.image_with_input(tex_a, display_size) if tex_a is not None else None
    draw_list = imgui.get_window_draw_list()
    if tex_a is None:
        imgui.set_cursor_screen_pos(origin)
        clicked = viewer.image_with_input(_blank(viewer), display_size)
    if wipe:
        tex_b = _texture(viewer, other, size, offline)
        x = origin.x + state.view.wipe_position * display_size[0]
        if tex_b is not None:
            draw_list.add_image(imgui.ImTextureRef(tex_b.glo), imgui.ImVec2(x, origin.y),
                                imgui.ImVec2(origin.x + display_size[0],
                                             origin.y + display_size[1]),
                                imgui.ImVec2(state.view.wipe_position, _v(other, 0)),
                                imgui.ImVec2(1.0, _v(other, 1)))
        draw_list.add_line(imgui.ImVec2(x, origin.y), imgui.ImVec2(x, origin.y + display_size[1]),
                           0xFFFFFFFF, 3.0)
        label(draw_list, imgui.ImVec2(origin.x + 8, origin.y + display_size[1] - 28),
               LABELS[name])
        label(draw_list, imgui.ImVec2(x + 8, origin.y + display_size[1] - 28), LABELS[other])
    if name == "raytrace" and view.ray_tree is not None:
        draw_ray_tree(state, draw_list, origin, display_size)
    # wrapped to the viewport, left of the fps readout (presenter fonts made them overlap),
    # in a corner where it hides no emitter (the Cornell light: what the path tracer's first
    # samples show)
    text = status_line(state)
    x, y, wrap = status_place(display_size, lambda w: tuple(imgui.calc_text_size(text, False, w)),
                              emitter_rect(state.scene, display_size),
                              presenter.readout_width(state))
    label(draw_list, imgui.ImVec2(origin.x + x, origin.y + y), text, wrap)
    if clicked is not None:
        pick_ray_tree(state, name, clicked, display_size)
    if state.screenshot_requested:
        _screenshot_pipeline(viewer, tex_a)
    return True


def hides_gizmos(state) -> bool:
    """The radiosity pipeline lights with emitters and the lights it uses: a light it does
    not use (a raster stand-in for the ceiling quad) has no gizmo there, where it would cover
    the shooting patch."""
    if current(state) != "radiosity" or state.view.compare:
        return False
    from shadelab.radiosity.direct import direct_lights

    return not direct_lights(state.scene)


def draw_on_top(state, origin, display_size: tuple[int, int]) -> None:
    """After the gizmos: the shooting patch's outline, so nothing hides it."""
    view = state.view.pipeline_view
    if view is None or current(state) != "radiosity" or state.view.compare \
            or view.name != "radiosity" or view.shooter is None or view.stats.get("done"):
        return
    outline = shooter_outline(state.scene, display_size, view.shooter)
    if outline is None:
        return
    thick = 5.0 if state.view.presenter else 3.0
    draw_list = imgui.get_window_draw_list()
    points = [imgui.ImVec2(origin.x + x, origin.y + y) for x, y in outline]
    draw_list.add_polyline(points, SHOOTER_HALO, thick + 4.0, imgui.ImDrawFlags_.closed)
    draw_list.add_polyline(points, SHOOTER_ABGR, thick, imgui.ImDrawFlags_.closed)
    index = view.stats.get("shooter_index")
    if index is not None:   # named just below its outline
        low = outline[:, 1].max() + thick + 4.0
        label(draw_list, imgui.ImVec2(origin.x + float(outline[:, 0].min()), origin.y + low),
              f"shooting: patch {index}")
def emitter_rect(scene, size: tuple[int, int]) -> tuple[float, float, float, float] | None:
    """Screen bounds (x0, y0, x1, y1) in a viewport of ``size`` of the objects whose material
    emits, clipped to it; None when no emitter is in view."""
    from shadelab.geometry.mesh import object_mesh

    points = [object_mesh(obj, i, scene.base_dir).vertices for i, obj in enumerate(scene.objects)
              if max(scene.materials[obj.material].emission) > 0.0]
    if not points:
        return None
    xy, front = project(scene, size, np.concatenate(points))
    if not front.any():
        return None
    (x0, y0), (x1, y1) = xy[front].min(axis=0), xy[front].max(axis=0)
    x0, y0, x1, y1 = max(x0, 0.0), max(y0, 0.0), min(x1, size[0]), min(y1, size[1])
    return (float(x0), float(y0), float(x1), float(y1)) if x0 < x1 and y0 < y1 else None


def status_place(size: tuple[int, int], measure, emitters, readout: float = 0.0,
                 margin: float = 8.0) -> tuple[float, float, float]:
    """(x, y, wrap) of the status box in a viewport of ``size``: top left, wrapped before the
    fps readout; where that box would cover the ``emitters`` rectangle (:func:`emitter_rect`),
    bottom left; where that covers them too, top left wrapped to end before them.
    ``measure(wrap)`` is the text's (width, height) wrapped at ``wrap`` pixels."""
    wrap = max(size[0] - 2 * margin - readout, 80.0)
    w, h = measure(wrap)

    def free(x, y, width, height):
        if emitters is None:
            return True
        x0, y0, x1, y1 = emitters
        pad = 4.0   # the box's own padding (label) and a pixel of air
        return x + width + pad <= x0 or x - pad >= x1 or y + height + pad <= y0 or y - pad >= y1

    if free(margin, margin, w, h):
        return margin, margin, wrap
    bottom = size[1] - margin - h
    if bottom > margin and free(margin, bottom, w, h):
        return margin, bottom, wrap
    narrow = max(emitters[0] - 2 * margin, 80.0)
    return margin, margin, min(narrow, wrap)


def _v(name: str, end: int) -> float:
    """The texture's v at the top (end 0) / bottom (1): GL panes are bottom-up, and the
    offline images are uploaded bottom-up too, so one image call shows them all."""
    return 1.0 - end


def _blank(viewer: ViewportHost):
    vp = viewer.viewport
    if "pipeline_blank" not in vp.images:
        vp.upload_image("pipeline_blank", np.zeros((8, 8, 3), np.uint8))
    return vp.images["pipeline_blank"]


def _texture(viewer: ViewportHost, name: str, size: tuple[int, int], offline: list):
    """The display texture of pipeline ``name`` (raster: rendered now if its inputs changed)."""
    state, vp = viewer.state, viewer.viewport
    view = view_of(state)
    exposure = state.scene.render.exposure
    if name in ("raytrace", "pathtrace"):
        if offline and offline[0] != name:
            return None
        if view.name != name and view.version < 0:
            return None
        return vp.images.get("pipeline")
    if name == "radiosity":
        if view.soup is None or view.name != "radiosity":
            return None
        # drawn again only when the triangles, the camera or a toggle changed: an idle frame
        # of the slide does no work proportional to the patches (issue 19.1)
        soup = viewport_soup(state, view.soup)
        grid = state.view.show_wireframe or state.view.radiosity_patches
        key = (view.version, id(soup), size, id(state.scene), state.scene_version,
               state.scene.version, grid, exposure, vp.line_width)
        if view.raster_key.get(name) == key and "pipeline_radiosity" in vp.panes:
            return vp.panes["pipeline_radiosity"].display
        view.raster_key[name] = key
        pane = vp.pane("pipeline_radiosity", size)
        vp.draw_colored_triangles(pane, state.scene, soup)
        if grid:
            vp.draw_lines(pane, patch_edges(view.soup), exposure)
        return vp.present(pane, exposure)
    shading, visibility = RASTER[name]
    key = (id(state.scene), state.scene_version, state.scene.version, size, name)
    pane_key = f"pipeline_{name}"
    if view.raster_key.get(name) != key or pane_key not in vp.panes:
        view.raster_key[name] = key
        scene = state.scene
        if (scene.render.shading, scene.render.visibility) != (shading, visibility):
            scene = clone_scene(scene)
            scene.render.shading, scene.render.visibility = shading, visibility
        pane = vp.draw_scene(pane_key, scene, size, shading, scene.render.specular)
        vp.present(pane, exposure)
    return vp.panes[pane_key].display


def _screenshot_pipeline(viewer: ViewportHost, texture) -> None:
    """The S key in an offline pipeline: the pipeline's image as a PNG."""
    from PIL import Image

    state = viewer.state
    path, state.screenshot_requested = state.screenshot_requested, ""
    if texture is None:
        state.error = f"screenshot '{path}': no image yet"
        return
    w, h = texture.size
    data = np.frombuffer(texture.read(), np.uint8).reshape(h, w, 4)[::-1, :, :3]
    try:
        Image.fromarray(np.ascontiguousarray(data)).save(path)
        state.status = f"screenshot {path}"
    except (OSError, ValueError) as exc:
        state.error = f"screenshot '{path}': cannot write ({exc})"

