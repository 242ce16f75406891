"""The interactive viewer: imgui-bundle docking layout, viewport in the middle.

GL resources are created in ``callbacks.post_init`` (moderngl attaches to the window's
context) and freed in ``callbacks.before_exit``. Panels live in :mod:`shadelab.ui.panels`; this
module holds the viewport window, the shortcut table and the per-frame bookkeeping (undo
snapshots, autosave, window title).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable

import moderngl
import numpy as np
from imgui_bundle import hello_imgui, imgui, immapp

from shadelab.geometry.mesh import geometry_key, scene_meshes
from shadelab.lab import (
    camera_control,
    lesson,
    overlays,
)
from shadelab.lab.autosave import Autosave
from shadelab.lab.recorder import FrameRecorder
from shadelab.lab.state import (
    AppState,
)
from shadelab.shading.codes import terms_mask
from shadelab.startup import resume_gc
from shadelab.ui import (
    compare_view,
    equation_panel,
    gizmos,
    layout,
    lights_panel,
    materials_panel,
    objects_panel,
    offline,
    panels,
    pipeline_viewport,
    pipelines,
    presenter,
    radiosity_view,
    scene_labels,
    scene_panel,
    stage,
)
from shadelab.ui.followups import FollowUps, ViewerOptions, write_window_screenshot
from shadelab.ui.frame import guarded
from shadelab.ui.offline import draw_offline_panel
from shadelab.ui.viewport_reads import update_probe, write_viewport_screenshot


class LazyPanels:
    """A panel module imported when one of its windows first draws after start-up: the
    windows behind a tab (Exercise, Studies, Algorithms, Ray tree) and what they import
    (exercises, studies, the ray tree's layout) stay off the path to the first frame. (The
    first frames, before the dock layout applies, draw every window: those draw nothing.)"""

    FIRST_FRAMES = 2

    def __init__(self, module: str):
        self.module = f"shadelab.ui.{module}"

    def __getattr__(self, name: str) -> Callable:
        module = self.module

        def draw(state: AppState) -> bool:
            import importlib
            import sys

            if module not in sys.modules and state.frame < LazyPanels.FIRST_FRAMES:
                return False
            return getattr(importlib.import_module(module), name)(state)

        draw.__name__ = draw.__qualname__ = name
        return draw


exercise_panel = LazyPanels("exercise_panel")
render_panel = LazyPanels("render_panel")
studies_panel = LazyPanels("studies_panel")
ray_tree_panel = LazyPanels("ray_tree_panel")

PRESENTER_SCALE = 1.8      # font scale of presenter mode
GC_RESUME_FRAME = 3        # the garbage collector runs again by then, first frame or not
WARM_JOBS_AT_FRAME = 60    # start the offline-job process once the window is up
BENCH_SETTLE_S = 30.0     # the bench waits at most this long for the start-up warm-up
SETTLE_FRAME_S = 0.05     # meanwhile a frame every 50 ms, near an idling viewer's rate
# The viewport's display pass goes straight into the window, under imgui's draw lists, where
# the image is shown pixel for pixel (ViewportHost.to_window): imgui's window-sized textured
# quad of it was ~4.6 ms of a 1024x768 frame on llvmpipe. False: always through the texture
WINDOW_PASS = True
WINDOW_BG = imgui.ImVec4(0.06, 0.06, 0.06, 1.0)  # the window's clear before the theme's is known


# ---------------------------------------------------------------- shortcuts


TAB_WORD = "Materials"   # dock tabs shrink no narrower than this word, then scroll


def _set(attr: str, value) -> Callable[[AppState], None]:
    def action(state: AppState) -> None:
        setattr(state.scene.render, attr, value)
        state.mark_edited()
    return action


def _toggle(attr: str) -> Callable[[AppState], None]:
    """A shortcut that switches the ViewState field ``attr`` (``state.view``)."""
    def action(state: AppState) -> None:
        setattr(state.view, attr, not getattr(state.view, attr))
    return action


def _toggle_blinn(state: AppState) -> None:
    render = state.scene.render
    render.specular = "phong" if render.specular == "blinn" else "blinn"
    state.mark_edited()


def _save(state: AppState) -> None:
    scene_panel.save_here(state)


K = imgui.Key
# Chords are plain ints: OR-ing two imgui.Key members (an IntFlag) raises AttributeError in
# Python < 3.11.4's enum (Debian 12's python3 is 3.11.2).
CTRL = int(imgui.Key.mod_ctrl)
# (key chord, shown as, what it does, action) — the help overlay lists this table.
SHORTCUTS = (
    (K._1, "1", "flat shading", _set("shading", "flat")),
    (K._2, "2", "Gouraud shading", _set("shading", "gouraud")),
    (K._3, "3", "Phong shading", _set("shading", "phong")),
    (K.b, "B", "Blinn-Phong / Phong specular", _toggle_blinn),
    (K.w, "W", "wireframe", _toggle("show_wireframe")),
    (K.n, "N", "vertex normal glyphs", _toggle("show_normals")),
    (K.l, "L", "object and material names", _toggle("show_names")),
    (K.c, "C", "compare 2x2", _toggle("compare")),
    (K.d, "D", "difference heat map (compare)", _toggle("diff_enabled")),
    (K.r, "R", "reset view", AppState.reset_view),
    (K.s, "S", "screenshot of the viewport", scene_panel.screenshot),
    (K.f, "F", "presenter mode (large fonts, the stage)", presenter.toggle_presenter),
    (K.h, "H", "this help", _toggle("show_help")),
    (K.f1, "F1", "this help", _toggle("show_help")),
    (K.tab, "Tab", "the stage (viewport and step controls) / every panel",
     presenter.toggle_panels),
    (K.f11, "F11", "fullscreen", presenter.toggle_fullscreen),
    (K.page_down, "PgDn", "next lesson step", lesson.next_step),
    (K.page_up, "PgUp", "previous lesson step", lesson.previous_step),
    (CTRL | int(K.z), "Ctrl+Z", "undo", AppState.undo),
    (CTRL | int(K.y), "Ctrl+Y", "redo", AppState.redo),
    (CTRL | int(K.s), "Ctrl+S", "save the preset", _save),
)
MOUSE_HELP = (("left drag", "orbit"), ("right / middle drag", "pan"), ("wheel", "zoom"),
              ("left click", "probe the pixel"))


def handle_shortcuts(state: AppState) -> None:
    """Run the action of each pressed chord (not while typing in a text field)."""
    if imgui.get_io().want_text_input:
        return
    for chord, _, _, action in SHORTCUTS:
        if imgui.is_key_chord_pressed(chord):
            action(state)


def draw_help_overlay(state: AppState) -> None:
    if not state.view.show_help:
        return
    imgui.set_next_window_bg_alpha(0.9)
    expanded, opened = imgui.begin("Help", True, imgui.WindowFlags_.always_auto_resize)
    if expanded:
        for _, keys, what, _ in SHORTCUTS:
            imgui.text(f"{keys:>8}  {what}")
        imgui.separator()
        for keys, what in MOUSE_HELP:
            imgui.text(f"{keys:>20}  {what}")
    imgui.end()
    if not opened:
        state.view.show_help = False


# ---------------------------------------------------------------- the viewer


@dataclass
class Viewer:
    """The viewer window: the panels' AppState and the GL side (viewport, GPU requests).

    Implements :class:`shadelab.ui.viewport_host.ViewportHost`, what the viewport layouts
    (compare grid, presenter, pipelines) may ask of it."""

    state: AppState
    options: ViewerOptions
    viewport: object = None            # shadelab.ui.viewport.Viewport, made in post_init
    gpu: object = None                 # shadelab.ui.gpu_side.GpuSide: serves state.gpu
    pointer: camera_control.PointerDrag = field(  # the press over the viewport: click or drag
        default_factory=camera_control.PointerDrag)
    autosave: Autosave = field(default_factory=Autosave)  # the session file, now and then
    title: str = ""
    recorder: FrameRecorder = field(default_factory=FrameRecorder)  # frame times, the bench
    _line_cache: dict = field(default_factory=dict)
    _frame_key: tuple = ()
    _window_pass: tuple | None = None     # the viewport's display pass into the window, due
    last_window_rect: tuple | None = None  # where it went last (x, y from the bottom, w, h)
    window_passes: dict = field(default_factory=lambda: {"display": 0, "copy": 0})  # so far
    warm_after_first_frame: bool = False  # spawn the pipeline worker after the first frame
    bench_frame0: int | None = None       # the bench's phases count from this frame (settled)
    followups: FollowUps = field(init=False)  # what the command line asked for

    def __post_init__(self) -> None:
        self.followups = FollowUps(self.options)
        self.recorder.breakdown = bool(self.options.bench_json)  # the frame's parts, timed

    # ------------------------------------------------------------ GL lifetime
    def post_init(self) -> None:
        from shadelab.gl.context import attach_to_current
        from shadelab.ui.gpu_side import GpuSide
        from shadelab.ui.viewport import Viewport

        self.viewport = Viewport(attach_to_current())
        self.gpu = GpuSide(self.viewport)
        self.gpu.flush(self.state.gpu)  # attached: panels may queue work from the first frame
        from shadelab.gl.target import max_msaa_samples

        self.state.view.msaa_limit = max_msaa_samples(self.viewport.ctx)
        from shadelab.ui.dialogs import install_drop_callback

        install_drop_callback()
        self.followups.start(self.state,
                             hello_imgui.get_runner_params().docking_params.dockable_windows)

    def before_exit(self) -> None:
        self.state.offline.runner.shutdown()
        pipeline_view = self.state.view.pipeline_view
        if pipeline_view is not None and pipeline_view.runner is not None:
            pipeline_view.runner.shutdown()
        prefetched = self.state.walk.prefetch
        if prefetched is not None and prefetched.runner is not None:
            prefetched.runner.shutdown()
        if self.state.studies.run is not None:
            self.state.studies.run.shutdown()
        if self.options.autosave:
            self.autosave(self.state, force=True)
        if self.options.bench_json:
            self.recorder.write(self.options.bench_json, self.options.window_size,
                                pipelines.bench_report(self.state)  # jobs: first_image_s...
                                | self.followups.bench_extra()
                                | {"triangles": self.triangles(),
                                   "panels_visible": visible_panels()})
        if self.gpu is not None:
            self.gpu.release()
            self.gpu = None
        if self.viewport is not None:
            self.viewport.release()
            self.viewport = None

    def triangles(self) -> int | None:
        """The scene's triangle count (the bench's report), None when a mesh does not load."""
        try:
            return sum(len(m.faces) for m in scene_meshes(self.state.scene))
        except Exception:  # a broken edit: the report is still written
            return None

    # ------------------------------------------------------------ viewport window
    def draw_viewport_window(self) -> None:
        state = self.state
        origin = imgui.get_cursor_screen_pos()
        avail = imgui.get_content_region_avail()
        # the caption gets its own band under the image: it never hides the scene; on stage
        # the step's controls get a strip under the caption
        band = presenter.caption_band(state, avail.x)
        strip = stage.strip_height(state)
        size = (max(int(avail.x), 16), max(int(avail.y - band - strip) - 4, 16))
        if size != state.view.viewport_size and state.probe.pixel is not None:
            state.probe.requested = True  # the same pixel shows another point now
        state.view.viewport_size = size
        if state.walk.lesson is not None:   # the next step's viewport (its prefetch's size)
            state.walk.next_size = (size[0], max(int(avail.y - presenter.next_step_band(
                state, avail.x) - strip) - 4, 16))
        if state.view.compare:
            with self.recorder.part("scene"):
                compare_view.draw_compare(self, size)
        else:
            self.draw_main(size)
            scene_labels.draw(state, origin, size)   # values, names, arrow names, probe sum
        # the caption and fps readout first: nothing the gizmo does to the draw list's clip
        # rect can hide them
        presenter.draw_viewport_extras(state, origin, size, self.recorder.redrawn, band)
        presenter.draw_lesson_buttons(state, origin, size, band)
        stage.draw_strip(state, imgui.ImVec2(origin.x, origin.y + avail.y - strip), avail.x,
                         strip)
        if not state.view.compare and not pipeline_viewport.hides_gizmos(state):
            gizmos.draw(state, origin, size)
        pipeline_viewport.draw_on_top(state, origin, size)   # the shooting patch, over all
        self.recorder.viewport_shown = True
        if state.error:
            imgui.set_cursor_pos(imgui.ImVec2(12, 40))
            imgui.text_colored(panels.ERROR_COLOR, f"Error: {state.error}")

    def image_with_input(self, texture, size: tuple[int, int]) -> tuple[float, float] | None:
        """Show the texture; handle orbit/pan/zoom; return the clicked pixel, if any."""
        state = self.state
        origin = imgui.get_cursor_screen_pos()
        if texture is not None:   # None: drawn into the window under imgui (to_window)
            imgui.image(imgui.ImTextureRef(texture.glo), imgui.ImVec2(*size),
                        uv0=imgui.ImVec2(0, 1), uv1=imgui.ImVec2(1, 0))
            imgui.set_cursor_screen_pos(origin)
        if gizmos.wants_mouse():  # ImGuizmo activates only when no item is hovered
            imgui.dummy(imgui.ImVec2(*size))
            return None
        imgui.invisible_button("viewport_input", imgui.ImVec2(*size),
                               imgui.ButtonFlags_.mouse_button_left
                               | imgui.ButtonFlags_.mouse_button_right
                               | imgui.ButtonFlags_.mouse_button_middle)
        io = imgui.get_io()
        camera = state.scene.camera
        pointer = (io.mouse_pos.x, io.mouse_pos.y)
        if imgui.is_item_activated():  # motion counts from here, not from the last position
            self.pointer.press(pointer)
        if imgui.is_item_active():
            dx, dy = self.pointer.move(pointer)
            if (dx or dy) and not gizmos.capturing():
                camera_control.drag(camera, dx, dy, imgui.is_mouse_down(imgui.MouseButton_.left),
                                    size[1], size[1], size[0])
                state.mark_edited()
        if imgui.is_item_hovered() and io.mouse_wheel:
            camera_control.zoom(camera, io.mouse_wheel)
            state.mark_edited()
        if imgui.is_item_deactivated() and self.pointer.is_click \
                and imgui.is_mouse_released(imgui.MouseButton_.left):
            mouse = io.mouse_pos
            return mouse.x - origin.x, mouse.y - origin.y
        return None

    def frame_key(self, size: tuple[int, int]) -> tuple:
        """Everything the viewport image depends on; an unchanged key reuses the last image.

        The scene counts by its edit counter (``Scene.version``: any change in it, announced by
        ``mark_edited`` or not) and by which scene it is (``scene_version``: loads, undo)."""
        s, v = self.state, self.state.view
        return (id(s.scene), s.scene_version, s.scene.version, size, v.compare, v.diff_enabled,
                v.diff_pair, v.diff_scale, v.show_wireframe, v.show_normals, v.normal_length,
                s.probe.version, s.offline.overlay_version, s.offline.show_radiosity, v.tonemap,
                v.show_clipping, presenter.line_px(s), v.antialias, v.msaa, v.terms_off,
                v.show_face_normals, v.show_normal_diff, v.normal_diff_modes)

    def unchanged(self, size: tuple[int, int]) -> bool:
        """True when the last image is still right (idle frames only redraw the GUI)."""
        key = self.frame_key(size)
        redraw = self.recorder.force_redraw or self.state.probe.requested \
            or bool(self.state.screenshot_requested) or key != self._frame_key
        self._frame_key = key
        self.recorder.redrawn = redraw
        return not redraw

    def draw_main(self, size: tuple[int, int]) -> None:
        state, vp = self.state, self.viewport
        scene = state.scene
        if pipeline_viewport.draw(self, size):  # an offline pipeline or the wipe took the viewport
            return
        display_size, size = size, self.render_size(size)
        if "main" in vp.panes and self.unchanged(size):
            pane = vp.panes["main"]
            if pane.shown is not None and self.to_window(pane, *pane.shown, display_size,
                                                         idle=True):
                texture = None
            else:
                texture = vp.display_texture(pane)
            self._handle_click(self.image_with_input(texture, display_size), display_size)
            return
        self.recorder.begin("scene")  # the bench's breakdown: PASS 1-5 (read-backs apart)
        # --- PASS 1-2: the scene into the float target (the Renderer's passes), or the solved
        # radiosity meshes, Gouraud-interpolated (view-independent: walk around them)
        radiosity = state.offline.show_radiosity and state.offline.radiosity_soup is not None
        if radiosity:
            pane = vp.pane("main", size, self.samples())
            vp.draw_colored_triangles(pane, scene, state.offline.radiosity_soup)
        else:
            pane = vp.draw_scene("main", scene, size, scene.render.shading, scene.render.specular,
                                 self.samples(), terms_mask(state.view.terms_off))
        # --- PASS 3: the probe reads the GPU value before any overlay is drawn
        if state.probe.requested:
            with self.recorder.part("readback"):
                update_probe(state, vp, size, display_size, self.samples())
        # --- PASS 4: overlays (wireframe, normal glyphs, probe arrows)
        exposure = scene.render.exposure
        meshes = scene_meshes(scene)
        vp.line_width = presenter.line_px(state) * size[0] / max(display_size[0], 1)
        if state.view.show_normal_diff:   # the surfaces painted by the angle between two rules
            degrees, full = scene_labels.heat_scale(state)
            vp.draw_lines(pane, overlays.normal_difference_soup(meshes, degrees, full), exposure,
                          mode=moderngl.TRIANGLES)
        if state.view.show_wireframe:
            vp.draw_lines(pane, self.cached_lines("wire", meshes), exposure)
        for kind in ("normals", "face_normals"):
            if getattr(state.view, "show_" + kind):
                vp.draw_lines(pane, self.cached_lines(kind, meshes), exposure)
        if state.probe.result is not None:   # a fixed share of the view, heads inside it
            specs = overlays.probe_arrow_specs(state.probe.result, scene.camera,
                                               size[0] / max(size[1], 1))
            vp.draw_lines(pane, overlays.arrow_lines(specs), exposure, depth_test=False)
        if state.offline.ray_tree is not None:
            lines = overlays.ray_tree_lines(state.offline.ray_tree, overlays.scene_diagonal(meshes))
            vp.draw_lines(pane, lines, exposure, depth_test=False)
        # --- PASS 5: exposure, tone map + sRGB for display
        texture = None
        if not self.to_window(pane, exposure, state.view.tonemap, state.view.show_clipping,
                              display_size):
            texture = vp.present(pane, exposure, tonemap=state.view.tonemap,
                                 clipping=state.view.show_clipping)
        if state.screenshot_requested:
            with self.recorder.part("readback"):
                write_viewport_screenshot(state, vp, state.screenshot_requested)
            state.screenshot_requested = ""
        self.recorder.end("scene")
        self._handle_click(self.image_with_input(texture, display_size), display_size)

    def to_window(self, pane, exposure: float, tonemap: str, clipping: bool,
                  display_size: tuple[int, int], idle: bool = False) -> bool:
        """Show ``pane`` by a display pass straight into the window, under imgui's draw lists
        (:meth:`present_window_pass`, before ImGui renders), instead of its texture drawn by
        imgui: where the pane is shown pixel for pixel at whole-pixel window coordinates, with
        the window's framebuffer at the GUI's scale; ``idle`` (the image unchanged): its
        display texture copied there instead. Returns whether it will be."""
        io = imgui.get_io()
        at = imgui.get_cursor_screen_pos()
        if not (WINDOW_PASS and self.viewport.ctx.screen is not None
                and pane.size == tuple(display_size)
                and at.x.is_integer() and at.y.is_integer()
                and io.display_framebuffer_scale.x == 1.0
                and io.display_framebuffer_scale.y == 1.0):
            return False
        height = int(io.display_size.y)
        rect = (int(at.x), height - int(at.y) - pane.size[1], *pane.size)
        self._window_pass = (pane, exposure, tonemap, clipping, rect, idle)
        return True

    def present_window_pass(self) -> None:
        """The viewport's display pass into the window (before_imgui_render), if one is due."""
        due, self._window_pass = self._window_pass, None
        if due is not None and self.viewport is not None:
            pane, exposure, tonemap, clipping, rect, idle = due
            self.last_window_rect = rect
            self.window_passes["copy" if idle else "display"] += 1
            if idle:
                self.viewport.blit_to_window(pane, rect)
            else:
                self.viewport.present_to_window(pane, exposure, tonemap, clipping, rect)

    def samples(self) -> int:
        """MSAA samples of the scene pass: the Display panel's choice, within the GL's limit."""
        return max(1, min(self.state.view.msaa, self.state.view.msaa_limit or 1))

    def interacting(self) -> bool:
        """A slider or the camera is being dragged right now."""
        return self.recorder.force_interactive or (self.state.edit_pending
                                                   and imgui.is_any_item_active())

    def render_size(self, size: tuple[int, int]) -> tuple[int, int]:
        """The scene's resolution: the viewport's times the render scale (lower mid-drag)."""
        scale = self.state.view.render_scale
        if self.interacting():
            scale = min(scale, self.state.view.interactive_scale)
        scale *= self.state.view.antialias  # supersampled, filtered down by the display texture
        return max(int(size[0] * scale), 8), max(int(size[1] * scale), 8)

    def _handle_click(self, clicked, size: tuple[int, int]) -> None:
        if clicked is not None:
            x, y = int(clicked[0]), int(clicked[1])
            if 0 <= x < size[0] and 0 <= y < size[1]:
                self.state.probe.pixel, self.state.probe.requested = (x, y), True

    def cached_lines(self, kind: str, meshes) -> np.ndarray:
        scene, state = self.state.scene, self.state
        key = (kind, tuple(geometry_key(o, scene.base_dir) for o in scene.objects),
               scene.render.shading, state.view.normal_length)
        if key not in self._line_cache:
            if len(self._line_cache) > 8:
                self._line_cache.clear()
            if kind == "wire":
                lines = overlays.wireframe(meshes)
            elif kind == "face_normals":
                length = state.view.normal_length * overlays.scene_diagonal(meshes)
                lines = overlays.face_normal_glyphs(meshes, length)
            else:
                length = state.view.normal_length * overlays.scene_diagonal(meshes)
                lines = overlays.normal_glyphs(meshes, length, scene.render.shading)
            self._line_cache[key] = lines
        return self._line_cache[key]

    # ------------------------------------------------------------ per frame
    def begin_frame(self) -> None:
        """Before any panel draws: the GPU work and images the panels queued last frame."""
        if self.gpu is not None:
            with self.recorder.part("gpu_requests"):
                guarded(lambda: self.gpu.flush(self.state.gpu), "GPU requests",
                        self.report_error)
            guarded(lambda: offline.update(self.state), "offline job", self.report_error)
        gizmos.begin_frame()

    def panel(self, draw: Callable[[AppState], bool]) -> Callable[[], None]:
        where = draw.__name__.removeprefix("draw_").removesuffix("_panel").strip("_") + " panel"

        def gui() -> None:
            layout.push_label_room()
            edited = guarded(lambda: draw(self.state), where, self.report_error)
            imgui.pop_item_width()
            if edited:
                self.state.mark_edited()
        return gui

    def report_error(self, message: str) -> None:
        """An error a frame raised: shown on the status line and in the viewport."""
        self.state.error = message

    def end_frame(self) -> None:
        """Shortcuts, undo snapshots, autosave, title, scripted exit."""
        state = self.state
        handle_shortcuts(state)
        if state.walk.lesson is not None and state.walk.lesson.step is None \
                and not lesson.go_to(state, 0):  # a lesson just opened (Open, drop): step 1
            state.walk.lesson = None                  # (its error is on the status line)
        presenter.end_frame(self)
        draw_help_overlay(state)
        scale = PRESENTER_SCALE if state.view.presenter else 1.0
        style = imgui.get_style()
        if style.font_scale_main != scale:  # only on change: a new scale re-bakes glyphs
            style.font_scale_main = scale
        # dock tabs shrink no narrower than a word ("Materials"), then scroll: at 1024x768
        # in presenter mode they had shrunk to "Mate..." and "O..."
        style.tab_min_width_shrink = imgui.calc_text_size(TAB_WORD).x \
            + 2.0 * style.frame_padding.x + imgui.get_font_size()   # + the close button
        if state.edit_pending and not imgui.is_any_item_active() and not gizmos.capturing():
            state.commit_edit()
        if self.options.autosave:
            self.autosave(self.state)
        self.update_title()
        state.frame += 1
        if state.frame == WARM_JOBS_AT_FRAME and not (self.options.frames
                                                      or self.options.test_function) \
                and state.offline.runner.worker is not None:
            state.offline.runner.worker.warm()  # after start-up: the first job then starts at once
        frame0 = 0
        if self.options.bench_json and self.options.frames:
            frame0 = self.bench_phase(state)
        if self.followups.end_frame(state, frame0):  # --frames done (after --job, --study...)
            hello_imgui.get_runner_params().app_shall_exit = True

    def bench_phase(self, state: AppState) -> int:
        """The bench's phases (idle, redraw, drag) count from the frame the viewer settled:
        the start-up warm-up done (the job process loading the offline kernels takes a core
        for a few seconds after the first frame; frames measured then time the warm-up, not
        the viewer), or BENCH_SETTLE_S after the first frame. Returns that frame (state.frame
        + 1 while not settled: --frames does not count yet)."""
        recorder = self.recorder
        if self.bench_frame0 is None:
            view = state.view.pipeline_view
            started = not self.warm_after_first_frame or (view is not None and view.warm_started)
            shown = bool(recorder.first_frame)
            waited = shown and time.perf_counter() - recorder.first_frame > BENCH_SETTLE_S
            if shown and ((started and not pipelines.warming(state)) or waited):
                self.bench_frame0 = state.frame
                recorder.settled = time.perf_counter()
        recorder.settling = self.bench_frame0 is None
        if self.bench_frame0 is None:
            # as an idle viewer does (fps idling), leaving the warm-up its core; not before the
            # first frame is on screen (the warm-up starts after it; the sleep only delayed it)
            if recorder.first_frame:
                time.sleep(SETTLE_FRAME_S)
            return state.frame + 1
        recorder.set_phase(state.frame - self.bench_frame0, self.options.frames)
        return self.bench_frame0

    def frame_swapped(self) -> None:
        """After the frame is on screen (:meth:`FrameRecorder.frame_swapped`)."""
        first = self.recorder.frame_swapped()
        if first or self.state.frame >= GC_RESUME_FRAME:
            resume_gc()   # paused by 'shadelab view' for the start-up (shadelab.startup)
        if first and self.warm_after_first_frame:
            pipelines.warm(self.state)  # the job process imports while the user looks

    def update_title(self) -> None:
        title = self.state.title()
        if title == self.title:
            return
        self.title = title
        try:
            import glfw
            from imgui_bundle import glfw_utils

            glfw.set_window_title(glfw_utils.glfw_window_hello_imgui(), title)
        except Exception:  # no GLFW backend (tests with a mock): the title is cosmetic
            pass


# ---------------------------------------------------------------- layout and run


def _docking(viewer: Viewer) -> hello_imgui.DockingParams:
    def split(initial: str, new: str, direction, ratio: float) -> hello_imgui.DockingSplit:
        s = hello_imgui.DockingSplit()
        s.initial_dock, s.new_dock, s.direction, s.ratio = initial, new, direction, ratio
        return s

    def window(label: str, dock: str, gui: Callable[[], None]) -> hello_imgui.DockableWindow:
        w = hello_imgui.DockableWindow()
        w.label, w.dock_space_name, w.gui_function = label, dock, gui
        return w

    params = hello_imgui.DockingParams()
    params.docking_splits = [
        split("MainDockSpace", "LeftSpace", imgui.Dir.left, 0.24),
        split("MainDockSpace", "RightSpace", imgui.Dir.right, 0.36),
        split("RightSpace", "RightBottom", imgui.Dir.down, 0.40),
    ]
    p = viewer.panel
    params.dockable_windows = [
        window("Scene", "LeftSpace", p(scene_panel.draw_scene_panel)),
        window("Lights", "LeftSpace", p(lights_panel.draw_lights_panel)),
        window("Materials", "LeftSpace", p(materials_panel.draw_materials_panel)),
        window("Objects", "LeftSpace", p(objects_panel.draw_objects_panel)),
        window("Viewport", "MainDockSpace",
               lambda: guarded(viewer.draw_viewport_window, "viewport", viewer.report_error)),
        window("Equation & probe", "RightSpace", p(equation_panel.draw_equation_panel)),
        window("Studies", "RightSpace", p(studies_panel.draw_studies_panel)),
        window("Failure gallery", "RightSpace", p(studies_panel.draw_gallery_panel)),
        window("Offline render", "RightBottom", p(draw_offline_panel)),
        window("Algorithms", "LeftSpace", p(render_panel.draw_algorithms_panel)),
        window("Hemicube & F", "RightSpace", p(radiosity_view.draw_panel)),
        window("Exercise", "RightSpace", p(exercise_panel.draw_exercise_panel)),
        window("Ray tree", "RightSpace", p(ray_tree_panel.draw_ray_tree_panel)),
    ]
    for w in params.dockable_windows:
        # llvmpipe is fill-bound: the window clear (same color) replaces every panel's
        # background quad, about 16 ms a frame at 1280x720 on two cores.
        w.imgui_window_flags = imgui.WindowFlags_.no_background
    params.dockable_windows[0].focus_window_at_next_frame = True
    params.dockable_windows[5].focus_window_at_next_frame = True  # the right column's first tab
    return params


def visible_panels() -> list[str]:
    """The dock windows shown now (none on the stage: presenter mode with the panels hidden)."""
    try:
        windows = hello_imgui.get_runner_params().docking_params.dockable_windows
    except RuntimeError:      # no runner (a test without a window)
        return []
    return sorted(w.label for w in windows if w.is_visible)


def clear_with_window_bg(params: hello_imgui.RunnerParams | None = None) -> None:
    """The theme's window background becomes the window's clear color, and windows draw none.

    llvmpipe is fill-bound: the full-window windows (hello_imgui's dock space host, the
    presenter's viewport window) each drew a window-sized background quad, blended, over the
    clear: about 12 ms of a 1280x720 frame's CPU time, idle or not. ImGui draws no rect whose
    alpha is 0, so WindowBg gets alpha 0 and the clear takes the color that quad blended to
    over it: the same picture. (Dock windows already draw none; a window that wants one sets
    its alpha, as Help does.)"""
    style = imgui.get_style()
    bg = style.color_(imgui.Col_.window_bg)
    if bg.w > 0.0:
        window = (params or hello_imgui.get_runner_params()).imgui_window_params
        clear = window.background_color
        window.background_color = imgui.ImVec4(*(c * bg.w + under * (1.0 - bg.w) for c, under in
                                                 ((bg.x, clear.x), (bg.y, clear.y),
                                                  (bg.z, clear.z))), 1.0)
        style.set_color_(imgui.Col_.window_bg, imgui.ImVec4(bg.x, bg.y, bg.z, 0.0))


def runner_params(viewer: Viewer) -> hello_imgui.RunnerParams:
    params = hello_imgui.RunnerParams()
    params.app_window_params.window_title = viewer.state.title()
    params.app_window_params.window_geometry.size = viewer.options.window_size
    if viewer.options.fullscreen:
        params.app_window_params.window_geometry.full_screen_mode = \
            hello_imgui.FullScreenMode.full_screen_desktop_resolution  # borderless
        viewer.state.view.fullscreen = True
        presenter.mark_fullscreen_applied()
    elif viewer.options.maximized:
        params.app_window_params.window_geometry.window_size_state = \
            hello_imgui.WindowSizeState.maximized
    params.imgui_window_params.default_imgui_window_type = \
        hello_imgui.DefaultImGuiWindowType.provide_full_screen_dock_space
    params.imgui_window_params.enable_viewports = False
    # A single-sample window: imgui's flat panels gain nothing from MSAA, and on a software GL
    # every GUI pixel at 4 samples (hello_imgui's default) cost most of an idle frame (52 ->
    # 17 ms CPU at 1280x720 on 2 cores); the scene has its own MSAA target (Display panel).
    gl_options = hello_imgui.OpenGlOptions()
    gl_options.anti_aliasing_samples = 0
    params.renderer_backend_options.open_gl_options = gl_options
    params.imgui_window_params.background_color = WINDOW_BG
    params.callbacks.setup_imgui_style = lambda: clear_with_window_bg()  # after the theme
    params.callbacks.theme_changed = lambda: clear_with_window_bg()
    params.docking_params = _docking(viewer)
    params.ini_disable = True
    # Idle at a few fps when nothing moves (frees the CPU for offline jobs); the bench and the
    # GUI tests measure and drive every frame.
    params.fps_idling.enable_idling = not (viewer.options.bench_json or viewer.options.test_function
                                           or viewer.options.frames)
    params.callbacks.post_init = viewer.post_init
    params.callbacks.before_exit = viewer.before_exit
    params.callbacks.post_new_frame = viewer.begin_frame
    params.callbacks.after_swap = viewer.frame_swapped
    # the bench's breakdown of a frame: the GUI built (panels, viewport passes within), then
    # ImGui's draw lists drawn and the swap (FrameRecorder.frame_swapped ends that part)
    params.callbacks.pre_new_frame = lambda: viewer.recorder.begin("gui")
    params.callbacks.before_imgui_render = lambda: (viewer.recorder.end("gui"),
                                                    viewer.recorder.begin("gui_render"),
                                                    viewer.present_window_pass())
    params.callbacks.show_gui = lambda: guarded(viewer.end_frame, "frame", viewer.report_error)
    return params


def native_run(params, addons) -> None:
    """immapp's native runner. imgui-bundle wraps ``immapp.run`` with a tutorial helper that
    calls ``inspect.stack()`` (it reads the source of every frame on the stack: ~0.1 s of the
    ~1 s to the first frame) to decide whether to save a tutorial screenshot; in a notebook
    the wrapper also shows the final frame, so there it is kept."""
    import sys

    native = getattr(getattr(immapp, "immapp_cpp", None), "run", None)
    if native is None or "ipykernel" in sys.modules:
        immapp.run(params, addons)
    else:
        native(params, addons)


_running: list[Viewer] = []  # the viewer of this process's window while it runs


def running_viewer() -> Viewer | None:
    """The viewer whose window is open (GUI tests reach its GL side here; panels never)."""
    return _running[-1] if _running else None


def run_viewer(state: AppState, options: ViewerOptions) -> int:
    """Open the window and run until it is closed (or ``options.frames`` frames)."""
    viewer = Viewer(state, options)
    _running.append(viewer)
    try:
        return _run(viewer, state, options)
    finally:
        _running.remove(viewer)


def _run(viewer: Viewer, state: AppState, options: ViewerOptions) -> int:
    if options.test_function is None:
        state.view.pipeline = options.pipeline or state.view.pipeline
        if state.view.presenter:   # --presenter: the stage, Tab brings the panels
            state.view.hide_panels = True
        if state.view.pipeline in pipelines.OFFLINE:
            pipelines.warm(state)  # an offline view at start: its process spawns at once
        else:  # else once the first frame is up: on 2 cores its imports delay that frame
            viewer.warm_after_first_frame = True
    params = runner_params(viewer)
    addons = immapp.AddOnsParams(with_implot=True)
    if options.test_function is not None:
        from imgui_bundle.immapp import testing

        testing.run(test_function=lambda ctx: options.test_function(ctx, state),
                    runner_params=params, add_ons_params=addons)
    else:
        native_run(params, addons)
    if options.screenshot:
        write_window_screenshot(options.screenshot)
    return 0
