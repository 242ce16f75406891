"""Light gizmos in the viewport: every light drawn as a glyph (point: a star, spot: a cone,
directional: an arrow), the selected point or spot light draggable with ImGuizmo (ships in
imgui-bundle): its axes move it along x, y or z, its centre in the screen plane.

The Viewer calls :func:`begin_frame` after ImGui's new frame and :func:`draw` over the viewport
image; while :func:`capturing` the viewport does not orbit and edits stay open (one undo step
per drag).
"""

from __future__ import annotations

import math

import numpy as np
from imgui_bundle import imgui, imguizmo

from shadelab.lab.state import AppState
from shadelab.scene.camera import clip_from_view, tan_half_fov_y, view_from_world
from shadelab.shading.lights import light_kind

GIZMO = imguizmo.im_guizmo
GIZMO_SIZE = 0.12            # ImGuizmo's size, share of clip space
GLYPH_COLOR = 0xFF40E0FF     # ImGui ABGR: warm yellow
GLYPH_OFF_COLOR = 0xFF707070
SELECTED_COLOR = 0xFFFFFFFF

_using = False


def begin_frame() -> None:
    GIZMO.begin_frame()


def capturing() -> bool:
    """A gizmo is being dragged (or was, this frame)."""
    return _using


def wants_mouse() -> bool:
    """The mouse is on a gizmo (or dragging one): the viewport leaves the click to it."""
    return _using or bool(GIZMO.is_over())


def column_major(matrix: np.ndarray):
    return GIZMO.Matrix16([float(v) for v in np.asarray(matrix, dtype=np.float64).T.reshape(-1)])


def projector(state: AppState, size: tuple[int, int]):
    """world point -> (x, y) viewport pixels (None behind the eye), plus the two matrices."""
    cam = state.scene.camera
    span = float(np.linalg.norm(np.subtract(cam.target, cam.eye))) or 1.0
    view = view_from_world(cam)
    proj = clip_from_view(cam, size[0] / max(size[1], 1), far=max(1000.0 * span, cam.near * 10))
    clip_from_world = proj @ view

    def project(point) -> tuple[float, float] | None:
        p = clip_from_world @ np.append(np.asarray(point, dtype=np.float64), 1.0)
        if p[3] <= 1e-9:
            return None
        return ((p[0] / p[3] * 0.5 + 0.5) * size[0], (0.5 - p[1] / p[3] * 0.5) * size[1])
    return project, view, proj


def pixel_size_at(state: AppState, point, height: int, width: int = 0) -> float:
    """World length of one viewport pixel at ``point``'s depth (for tests and drag speeds);
    ``width`` (when known) lets a viewport narrower than the camera's fit aspect widen it."""
    cam = state.scene.camera
    forward = np.subtract(cam.target, cam.eye)
    forward = forward / np.linalg.norm(forward)
    depth = float(np.dot(np.subtract(point, cam.eye), forward))
    return 2.0 * depth * tan_half_fov_y(cam, width / max(height, 1)) / max(height, 1)


SURFACE_LIT = ("pathtrace", "radiosity")  # pipelines lit by the surface a stand-in stands for


def shown(state: AppState, light) -> bool:
    """False for a ``stand_in`` light in a pipeline that lights with the emitting surface it
    stands for (path tracing, radiosity): that surface is drawn, and the glyph and handle of
    a light that does nothing there would sit on it."""
    if not light.stand_in:
        return True
    from shadelab.lab.pipeline_view import current

    return current(state) not in SURFACE_LIT


def draw(state: AppState, origin, size: tuple[int, int]) -> bool:
    """Glyphs for every light and the ImGuizmo of the selected one; True when it moved."""
    global _using
    if not state.view.show_gizmos or not state.scene.lights:
        _using = False
        return False
    project, view, proj = projector(state, size)
    draw_list = imgui.get_window_draw_list()
    scale = 1.8 if state.view.presenter else 1.0
    cam = state.scene.camera
    span = float(np.linalg.norm(np.subtract(cam.target, cam.eye))) or 1.0
    selected = min(max(state.view.gizmo_light, 0), len(state.scene.lights) - 1)
    for i, light in enumerate(state.scene.lights):
        if not shown(state, light):
            continue
        color = (SELECTED_COLOR if i == selected else GLYPH_COLOR) if light.enabled \
            else GLYPH_OFF_COLOR
        _draw_glyph(draw_list, project, origin, light, color, scale, span)
    light = state.scene.lights[selected]
    if not shown(state, light):
        _using = False
        return False
    forward = np.subtract(cam.target, cam.eye) / span
    depth = float(np.dot(np.subtract(light.position, cam.eye), forward))
    if light_kind(light).at_infinity or (depth <= cam.near and not _using):
        # (a light beside or behind the eye: ImGuizmo returns early there and left its clip
        # rect on the window's draw list, which hid the lesson caption drawn after it)
        _using = False
        return False
    GIZMO.set_drawlist(draw_list)
    GIZMO.set_rect(origin.x, origin.y, float(size[0]), float(size[1]))
    GIZMO.set_gizmo_size_clip_space(GIZMO_SIZE * (1.3 if state.view.presenter else 1.0))
    matrix = np.eye(4)
    matrix[:3, 3] = light.position
    object_matrix = column_major(matrix)
    GIZMO.push_id(selected)
    moved = GIZMO.manipulate(column_major(view), column_major(proj), GIZMO.OPERATION.translate,
                             GIZMO.MODE.world, object_matrix)
    GIZMO.pop_id()
    _using = GIZMO.is_using()
    if moved:
        values = object_matrix.values
        light.position = (float(values[12]), float(values[13]), float(values[14]))
        state.mark_edited()
    return bool(moved)


def _draw_glyph(draw_list, project, origin, light, color: int, scale: float, span: float):
    thickness = 2.0 * scale

    def screen(p):
        q = project(p)
        return None if q is None else imgui.ImVec2(origin.x + q[0], origin.y + q[1])

    kind = light_kind(light)
    if kind.at_infinity:
        d = np.asarray(light.direction, dtype=np.float64)
        d = d / max(np.linalg.norm(d), 1e-12)
        start = screen(np.zeros(3) - d * 0.3 * span)
        end = screen(np.zeros(3))
        if start is not None and end is not None:
            _arrow(draw_list, start, end, color, thickness)
        return
    centre = screen(light.position)
    if centre is None:
        return
    r = 7.0 * scale
    draw_list.add_circle_filled(centre, r * 0.55, color)
    for k in range(8):
        a = k * math.pi / 4
        draw_list.add_line(imgui.ImVec2(centre.x + r * 0.8 * math.cos(a),
                                        centre.y + r * 0.8 * math.sin(a)),
                           imgui.ImVec2(centre.x + r * 1.5 * math.cos(a),
                                        centre.y + r * 1.5 * math.sin(a)), color, thickness)
    if kind.has_cone:
        d = np.asarray(light.direction, dtype=np.float64)
        d = d / max(np.linalg.norm(d), 1e-12)
        length = 0.25 * span
        radius = length * math.tan(math.radians(min(light.cone_angle, 80.0)))
        u = np.cross(d, [0.0, 1.0, 0.0] if abs(d[1]) < 0.9 else [1.0, 0.0, 0.0])
        u /= np.linalg.norm(u)
        v = np.cross(d, u)
        tip = np.asarray(light.position, dtype=np.float64)
        ring = [screen(tip + d * length + radius * (math.cos(t) * u + math.sin(t) * v))
                for t in np.linspace(0.0, 2 * math.pi, 25)]
        for a, b in zip(ring[:-1], ring[1:], strict=True):
            if a is not None and b is not None:
                draw_list.add_line(a, b, color, thickness * 0.75)
        for a in ring[:-1:6]:
            if a is not None:
                draw_list.add_line(centre, a, color, thickness * 0.75)


def _arrow(draw_list, start, end, color: int, thickness: float) -> None:
    draw_list.add_line(start, end, color, thickness)
    dx, dy = end.x - start.x, end.y - start.y
    length = math.hypot(dx, dy) or 1.0
    ux, uy = dx / length, dy / length
    head = 6.0 * thickness
    left = imgui.ImVec2(end.x - head * ux + head * 0.5 * uy, end.y - head * uy - head * 0.5 * ux)
    right = imgui.ImVec2(end.x - head * ux - head * 0.5 * uy, end.y - head * uy + head * 0.5 * ux)
    draw_list.add_triangle_filled(end, left, right, color)


def draw_selector(state: AppState) -> None:
    """In the Lights panel: which light the viewport's gizmo moves."""
    lights = state.scene.lights
    if not lights:
        return
    names = [light.name or f"light {i}" for i, light in enumerate(lights)]
    index = min(max(state.view.gizmo_light, 0), len(lights) - 1)
    _, state.view.gizmo_light = imgui.combo("gizmo moves", index, names)
    from shadelab.ui.layout import same_line_if_fits

    if same_line_if_fits("show", radio=True):
        imgui.same_line()
    _, state.view.show_gizmos = imgui.checkbox("show##gizmos", state.view.show_gizmos)
