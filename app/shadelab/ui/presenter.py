"""Presenter mode: fullscreen (F11), the viewport alone (Tab) with a caption, line widths
that scale with the presenter scale, an fps readout, and the display options (tone map,
clipping indicator, anti-aliasing).

The Viewer calls :func:`end_frame` once a frame and :func:`draw_viewport_extras` after the
viewport image; the Scene panel shows :func:`draw_display_panel`.
"""

from __future__ import annotations

from imgui_bundle import hello_imgui, imgui

from shadelab.lab.state import AppState
from shadelab.ui.layout import same_line_if_fits
from shadelab.ui.viewport_host import ViewportHost

PRESENTER_SCALE = 1.8          # font scale of presenter mode (ui/app.py applies it)
LINE_PX = 1.5                  # overlay line width at font scale 1, pixels
PRESENTER_LINE_PX = 3.5        # ... in presenter mode (>= 3 px: seen from the back row)
TONEMAPS = ("clamp", "reinhard")
TONEMAP_LABELS = {"clamp": "clamp to [0, 1]", "reinhard": "Reinhard x / (1 + x)"}
CAPTION_COLOR = 0xFFFFFFFF
CAPTION_SHADOW = 0xC0000000
PRESENTER_WINDOW = "##presenter viewport"


def line_px(state: AppState) -> float:
    """Overlay line width on screen, pixels: grows with the presenter scale."""
    if state.view.line_width > 0:
        return state.view.line_width
    return PRESENTER_LINE_PX if state.view.presenter else LINE_PX


def font_scale(state: AppState) -> float:
    return PRESENTER_SCALE if state.view.presenter else 1.0


# ---------------------------------------------------------------- shortcut actions


def toggle_panels(state: AppState) -> None:
    state.view.hide_panels = not state.view.hide_panels


def set_presenter(state: AppState, on: bool) -> None:
    """Presenter mode on: large fonts and the stage (the viewport with the step's controls,
    the dock panels hidden, Tab brings them back); off: the desk layout with its panels."""
    if on != state.view.presenter:
        state.view.hide_panels = on
    state.view.presenter = on


def toggle_presenter(state: AppState) -> None:
    set_presenter(state, not state.view.presenter)


def toggle_fullscreen(state: AppState) -> None:
    state.view.fullscreen = not state.view.fullscreen


# ---------------------------------------------------------------- fullscreen


_applied_fullscreen = False
_windowed_geometry: tuple[int, int, int, int] | None = None


def apply_fullscreen(state: AppState) -> None:
    """Switch the GLFW window to the monitor's resolution and back when ``state.view.fullscreen``
    changed (the window's monitor: the one under its centre)."""
    global _applied_fullscreen, _windowed_geometry
    if state.view.fullscreen == _applied_fullscreen:
        return
    _applied_fullscreen = state.view.fullscreen
    try:
        import glfw
        from imgui_bundle import glfw_utils

        window = glfw_utils.glfw_window_hello_imgui()
        if state.view.fullscreen:
            x, y = glfw.get_window_pos(window)
            w, h = glfw.get_window_size(window)
            _windowed_geometry = (x, y, w, h)
            monitor = monitor_of(glfw, (x + w // 2, y + h // 2))
            mode = glfw.get_video_mode(monitor)
            glfw.set_window_monitor(window, monitor, 0, 0, mode.size.width, mode.size.height,
                                    mode.refresh_rate)
        else:
            x, y, w, h = _windowed_geometry or (40, 40, 1600, 900)
            glfw.set_window_monitor(window, None, x, y, w, h, 0)
        state.status = "fullscreen" if state.view.fullscreen else "windowed"
    except Exception as exc:  # no GLFW window (a mock backend): say so, keep running
        state.error = f"fullscreen: {exc}"


def mark_fullscreen_applied() -> None:
    """The window opens fullscreen (hello_imgui's window params did it)."""
    global _applied_fullscreen
    _applied_fullscreen = True


def monitor_of(glfw, point: tuple[int, int]):
    for monitor in glfw.get_monitors() or []:
        mx, my = glfw.get_monitor_pos(monitor)
        mode = glfw.get_video_mode(monitor)
        if mx <= point[0] < mx + mode.size.width and my <= point[1] < my + mode.size.height:
            return monitor
    return glfw.get_primary_monitor()


# ---------------------------------------------------------------- panels hidden (Tab)


_hidden_labels: list[str] = []


def apply_panel_visibility(state: AppState) -> None:
    """Tab: every dock window hidden (the viewport is drawn in a window of its own)."""
    global _hidden_labels
    windows = hello_imgui.get_runner_params().docking_params.dockable_windows
    if state.view.hide_panels:
        # every frame: a window hello_imgui shows again (a tab focused at start, a lesson
        # step's focus) would otherwise be drawn over the stage
        for w in windows:
            if w.is_visible:
                if w.label not in _hidden_labels:
                    _hidden_labels.append(w.label)
                w.is_visible = False
    elif not state.view.hide_panels and _hidden_labels:
        for w in windows:
            if w.label in _hidden_labels:
                w.is_visible = True
        _hidden_labels = []


def draw_presenter_viewport(viewer: ViewportHost) -> None:
    """With the panels hidden: the viewport over the whole window."""
    state = viewer.state
    if not state.view.hide_panels:
        return
    vp = imgui.get_main_viewport()
    imgui.set_next_window_pos(vp.work_pos)
    imgui.set_next_window_size(vp.work_size)
    imgui.push_style_var(imgui.StyleVar_.window_padding, imgui.ImVec2(0, 0))
    imgui.push_style_var(imgui.StyleVar_.window_border_size, 0.0)
    flags = (imgui.WindowFlags_.no_decoration | imgui.WindowFlags_.no_move
             | imgui.WindowFlags_.no_saved_settings | imgui.WindowFlags_.no_docking
             | imgui.WindowFlags_.no_bring_to_front_on_focus
             | imgui.WindowFlags_.no_scroll_with_mouse)
    imgui.begin(PRESENTER_WINDOW, None, flags)
    imgui.pop_style_var(2)
    try:
        from shadelab.ui.frame import guarded

        guarded(viewer.draw_viewport_window, "viewport", viewer.report_error)
    finally:
        imgui.end()


# ---------------------------------------------------------------- layout that fits


NARROW_EM = 95.0     # below this many font heights of window width, one side column
DOCK_RATIOS = {"wide": {"LeftSpace": 0.24, "RightSpace": 0.36, "RightBottom": 0.40},
               "narrow": {"LeftSpace": 0.46, "RightSpace": 0.36, "RightBottom": 0.40}}
_layout = "wide"
_home: dict[str, str] = {}   # window label -> its dock space in the wide layout


def layout_for(width: float, font_px: float) -> str:
    """'narrow' (the right column's panels join the left one, which widens) when the window
    is less than NARROW_EM font heights wide, else 'wide'."""
    return "narrow" if width < NARROW_EM * font_px else "wide"


def apply_layout(state: AppState) -> str:
    """Re-dock the panels when the window's width in font heights crosses NARROW_EM (a
    projector at 1024x768, presenter fonts), so labels and tables keep their room."""
    global _layout
    io = imgui.get_io()
    font_px = imgui.get_style().font_size_base * font_scale(state)
    wanted = layout_for(io.display_size.x, font_px)
    if wanted == _layout:
        return _layout
    params = hello_imgui.get_runner_params().docking_params
    if not _home:
        _home.update({w.label: w.dock_space_name for w in params.dockable_windows})
    for split in params.docking_splits:
        split.ratio = DOCK_RATIOS[wanted].get(split.new_dock, split.ratio)
    for w in params.dockable_windows:
        home = _home.get(w.label, w.dock_space_name)
        w.dock_space_name = "LeftSpace" if wanted == "narrow" and home.startswith("Right") \
            else home
    params.layout_reset = True
    _layout = wanted
    return wanted


# ---------------------------------------------------------------- in the viewport


def caption_text(state: AppState) -> str:
    """The lesson step's caption, or (panels hidden) the current equation and mode."""
    if state.walk.lesson is not None and state.walk.lesson.step is not None:
        return state.walk.lesson.caption()
    if not state.view.hide_panels:
        return ""
    from shadelab.ui.equation_panel import EQUATION, EQUATION_BLINN
    from shadelab.ui.panels import SHADING_LABELS

    render = state.scene.render
    equation = EQUATION_BLINN if render.specular == "blinn" else EQUATION
    mode = f"{SHADING_LABELS[render.shading]} shading"
    pipeline = state.view.pipeline
    if pipeline:
        mode += f", pipeline {pipeline}"
    if render.shadows != "none":
        mode += ", shadows"
    return f"{equation}\n{mode}  -  Tab: panels"


def caption_font_px(scale: float) -> float:
    """The caption's glyph height on screen: the base font size times the caption scale and
    the global factors (presenter, DPI), computed from the style rather than read from ImGui's
    current font state (issue 22: captions came out small after some steps)."""
    style = imgui.get_style()
    return style.font_size_base * scale * style.font_scale_main * style.font_scale_dpi


def _push_caption_font(scale: float) -> float:
    """Push the caption's size; the pixel size it draws at. Should ImGui's current size not
    follow the push (it keeps the old one in a frame where the window skips items), the
    computed size is used. A guard: the small captions of issue 22 did not reproduce here."""
    expected = caption_font_px(scale)
    imgui.push_font(None, imgui.get_style().font_size_base * scale)
    got = imgui.get_font_size()
    return got if abs(got - expected) <= 1.0 else expected


VALUE_SCALE = 0.6     # the probed values under the caption's terms, share of its font size
TERM_OFF_COLOR = 0xFF8C8C8C


def _u32(rgba) -> int:
    return imgui.color_convert_float4_to_u32(imgui.ImVec4(*rgba))


_layouts: dict[tuple, tuple] = {}   # (text, width, font px) -> (runs, line tops, height)


def caption_layout(text: str, width: float, scale: float) -> tuple[list, list, float, float]:
    """The caption's runs (:func:`shadelab.lab.caption_terms.layout`) wrapped to ``width``
    pixels at the caption's font, each line's top and the text's height (a row for the
    probed values under every line that carries a term: the band never changes with the
    probe), and the font px. Measured at the size it is drawn at."""
    from shadelab.lab.caption_terms import layout, line_count, lines_with_terms

    pad = 10.0 * scale / 1.4
    font_px = _push_caption_font(scale)
    key = (text, round(width, 1), round(font_px, 2))
    try:
        cached = _layouts.get(key)
        if cached is None:
            got = imgui.get_font_size()
            k = font_px / got if got > 0 else 1.0   # a stale current size: rescaled

            def measure(t: str) -> float:
                return imgui.calc_text_size(t).x * k
            runs = layout(text, max(width - 2 * pad, 50.0), measure)
            value_row = VALUE_SCALE * font_px + 2.0
            terms = lines_with_terms(runs)
            tops, y = [], 0.0
            for line in range(line_count(runs)):
                tops.append(y)
                y += font_px + (value_row if line in terms else 0.0)
            if len(_layouts) > 256:
                _layouts.clear()
            cached = _layouts[key] = (runs, tops, y)
    finally:
        imgui.pop_font()
    runs, tops, y = cached
    return runs, tops, y, font_px


def caption_height(text: str, width: float, scale: float) -> float:
    """Height of the caption band for ``text`` wrapped to ``width`` pixels (0 if no text)."""
    if not text:
        return 0.0
    pad = 10.0 * scale / 1.4
    return caption_layout(text, width, scale)[2] + 2.5 * pad


# The last caption's font px, line and glyph heights, recorded only while a GUI test sets
# RECORD_CAPTION (measuring the glyph every frame is work the lecture does not need); with it
# the terms drawn: term -> (item id, (x0, y0, x1, y1), value text)
RECORD_CAPTION = False
drawn_caption: dict = {}
drawn_terms: dict = {}


def draw_caption(draw, text: str, origin, size, scale: float,
                 height: float | None = None, state: AppState | None = None) -> None:
    """Large caption at the bottom of the ``size`` rect at ``origin``, wrapped to its width,
    on a dark band ``height`` high (:func:`caption_height`, measured here when not given).
    Its terms of the equation are drawn in their colours (the Equation & probe window's);
    with ``state`` each is a button that switches the term off and on in the image, and with
    a probe set its value at the probed point is written under it."""
    if not text:
        return
    pad = 10.0 * scale / 1.4
    if height is None:
        height = caption_height(text, size[0], scale)
    runs, tops, _, font_px = caption_layout(text, size[0], scale)
    font_size = _push_caption_font(scale)
    if RECORD_CAPTION:
        drawn_terms.clear()
    try:
        font = imgui.get_font()
        x0, y0 = origin.x + pad, origin.y + size[1] - height + pad
        draw.add_rect_filled(imgui.ImVec2(origin.x, origin.y + size[1] - height),
                             imgui.ImVec2(origin.x + size[0], origin.y + size[1]), 0xA0000000)
        for k, run in enumerate(runs):
            x, y = x0 + run.x, y0 + tops[run.line]
            color = CAPTION_COLOR
            if run.term:
                color = _term_color(state, run.term)
            draw.add_text(font, font_size, imgui.ImVec2(x + 1, y + 1), CAPTION_SHADOW, run.text)
            draw.add_text(font, font_size, imgui.ImVec2(x, y), color, run.text)
            if run.term:
                _live_term(draw, font, state, run, k, x, y, font_size)
        if RECORD_CAPTION:
            _record_caption(font, font_size)
    finally:
        imgui.pop_font()


def _term_color(state: AppState | None, term: str) -> int:
    from shadelab.lab.caption_terms import TERM_COLORS

    if state is not None and term in state.view.terms_off:
        return TERM_OFF_COLOR
    return _u32(TERM_COLORS[term])


def _live_term(draw, font, state: AppState | None, run, k: int, x: float, y: float,
               font_px: float) -> None:
    """One term of the caption: struck through when off, its probed value under it, and
    (with ``state``) a button over it that switches it."""
    from shadelab.lab.caption_terms import (
        TERM_COLORS,
        term_value_text,
        terms_switchable,
        toggle_term,
    )

    color = _term_color(state, run.term)
    off = state is not None and run.term in state.view.terms_off
    if off:
        mid = y + 0.55 * font_px
        draw.add_line(imgui.ImVec2(x, mid), imgui.ImVec2(x + run.width, mid), color, 2.0)
    value = ""
    if state is not None and (off or state.probe.result is not None):
        value = term_value_text(state.probe.result, run.term, off)
    value_px = VALUE_SCALE * font_px
    if value:
        draw.add_text(font, value_px, imgui.ImVec2(x, y + font_px + 1.0),
                      _u32(TERM_COLORS[run.term]) if not off else TERM_OFF_COLOR, value)
    if state is None or not terms_switchable(state):
        return
    rect = (x, y, x + run.width, y + font_px + value_px)
    imgui.set_cursor_screen_pos(imgui.ImVec2(x, y))
    if imgui.invisible_button(f"##term {run.term} {k}", imgui.ImVec2(run.width, rect[3] - y)):
        toggle_term(state, run.term)
    if imgui.is_item_hovered():
        imgui.set_mouse_cursor(imgui.MouseCursor_.hand)
        draw.add_line(imgui.ImVec2(x, y + font_px), imgui.ImVec2(x + run.width, y + font_px),
                      color, 2.0)
        imgui.set_item_tooltip(f"click: {run.term} {'on' if off else 'off'} in the image")
    if RECORD_CAPTION and run.term not in drawn_terms:
        drawn_terms[run.term] = (imgui.get_item_id(), rect, value)


def _record_caption(font, font_size: float) -> None:
    """What a GUI test reads of the caption just drawn (see RECORD_CAPTION)."""
    glyph = font.get_font_baked(font_size).find_glyph(ord("G"))
    tex = imgui.get_io().fonts.tex_data
    drawn_caption.update(px=font_size, line=imgui.calc_text_size("Gouraud").y,
                         glyph=glyph.y1 - glyph.y0, baked=font.get_font_baked(font_size).size,
                         uv=(glyph.v1 - glyph.v0) * (tex.height if tex else 0),
                         atlas=(tex.width, tex.height) if tex else (0, 0))


def fps_text(redrawn: bool) -> str:
    fps = imgui.get_io().framerate
    return f"{fps:5.1f} fps  {1000.0 / max(fps, 1e-6):5.1f} ms" + ("  redrawn" if redrawn else "")


def readout_width(state: AppState) -> float:
    """Screen width the fps readout takes at the viewport's top right (0 when hidden): the
    pipeline status line wraps before it instead of running under it."""
    return imgui.calc_text_size(fps_text(True)).x + 24.0 if state.view.fps_shown else 0.0


def caption_scale(state: AppState) -> float:
    return 1.4 if state.walk.lesson is not None else 1.0


def lesson_running(state: AppState) -> bool:
    return state.walk.lesson is not None and state.walk.lesson.step is not None


def lesson_captions(lesson) -> list[str]:
    """Every step's caption of ``lesson``, as the viewport shows them."""
    from shadelab.lab.lesson_file import LessonRun

    return [LessonRun(lesson, i).caption() for i in range(len(lesson.steps))]


def lesson_band_height(captions, measure) -> float:
    """The caption band kept for a whole lesson: the tallest of its captions, ``measure(text)``
    being one caption's band height (0 without captions). Pure: the scene keeps its size and
    place from step to step, so two steps compare cleanly."""
    return max((measure(text) for text in captions if text), default=0.0)


_lesson_bands: dict[tuple, float] = {}   # (captions, width, font px) -> their band height


def _lesson_band(state: AppState, width: float) -> float:
    captions = tuple(lesson_captions(state.walk.lesson.lesson))
    scale = caption_scale(state)
    style = imgui.get_style()
    key = (captions, round(width), round(style.font_size_base * scale * style.font_scale_main, 2))
    if key not in _lesson_bands:
        if len(_lesson_bands) > 64:
            _lesson_bands.clear()
        _lesson_bands[key] = lesson_band_height(
            captions, lambda text: caption_height(text, width, scale))
    return _lesson_bands[key]


def caption_band(state: AppState, width: float) -> float:
    """Height of the caption band the viewport keeps under its image (0: no caption); in a
    lesson it is measured once for all its steps (the tallest caption at this width and
    font) and holds a row for the Prev / Next buttons too (on stage they sit in the controls
    strip instead)."""
    if lesson_running(state):
        height = _lesson_band(state, width)
        if not height or _buttons_on_stage(state):
            return height
        return height + imgui.get_frame_height_with_spacing()
    return caption_height(caption_text(state), width, caption_scale(state))


def next_step_band(state: AppState, width: float) -> float:
    """The caption band the lesson's next step will keep (its prefetch renders at the size the
    viewport will have then): the lesson's one band."""
    return caption_band(state, width)


LESSON_BUTTONS = ("< Prev (PgUp)", "Next > (PgDn)")


def _buttons_on_stage(state: AppState) -> bool:
    """The lesson's Prev / Next buttons are in the stage's controls strip (ui/stage.py)."""
    from shadelab.ui.stage import strip_height

    return strip_height(state) > 0


def draw_lesson_buttons(state: AppState, origin, size, band: float) -> None:
    """Prev / Next at the bottom right of the caption band: in the viewport, so they stay in
    reach whichever panel a step brings forward (PageUp / PageDown do the same)."""
    if band <= 0 or not lesson_running(state) or _buttons_on_stage(state):
        return
    from shadelab.lab import lesson

    style = imgui.get_style()
    widths = [imgui.calc_text_size(label).x + 2 * style.frame_padding.x
              for label in LESSON_BUTTONS]
    x = origin.x + size[0] - sum(widths) - style.item_spacing.x - 8
    y = origin.y + size[1] + band + 4 - imgui.get_frame_height() - 4
    imgui.set_cursor_screen_pos(imgui.ImVec2(x, y))
    if imgui.button(LESSON_BUTTONS[0]):
        lesson.previous_step(state)
    imgui.same_line()
    if imgui.button(LESSON_BUTTONS[1]):
        lesson.next_step(state)


def draw_viewport_extras(state: AppState, origin, size, redrawn: bool,
                         band: float = 0.0) -> None:
    """The fps readout over the viewport image (origin: its top-left, screen; in the 2x2
    compare at the bottom right, clear of the panes' labels) and the caption in the ``band``
    pixels under it (over the image's bottom when no band was kept)."""
    draw = imgui.get_window_draw_list()
    if state.view.fps_shown:
        text = fps_text(redrawn)
        width = imgui.calc_text_size(text).x
        line = imgui.get_font_size()
        y = origin.y + size[1] - line - 6 if state.view.compare else origin.y + 4
        pos = imgui.ImVec2(origin.x + size[0] - width - 8, y)
        draw.add_rect_filled(imgui.ImVec2(pos.x - 4, pos.y - 2),
                             imgui.ImVec2(pos.x + width + 4, pos.y + line + 2), 0x90000000)
        draw.add_text(pos, 0xFFB0FFB0, text)
    _draw_toast(draw, state, origin, size)
    caption = caption_text(state)
    if band > 0:
        draw_caption(draw, caption, imgui.ImVec2(origin.x, origin.y + size[1]),
                     (size[0], band + 4), caption_scale(state), band,  # measured once a frame
                     state)
    else:   # over the image: its terms are not buttons (the image takes the clicks)
        draw_caption(draw, caption, origin, size, caption_scale(state))


def _draw_toast(draw, state: AppState, origin, size) -> None:
    """A short message centred at the viewport's top (a saved screenshot) while it lasts."""
    import time

    text, until = state.toast
    if not text or time.monotonic() > until:
        return
    width = imgui.calc_text_size(text).x
    line = imgui.get_font_size()
    pos = imgui.ImVec2(origin.x + max(8.0, (size[0] - width) / 2), origin.y + 8 + line)
    draw.add_rect_filled(imgui.ImVec2(pos.x - 8, pos.y - 4),
                         imgui.ImVec2(pos.x + width + 8, pos.y + line + 4), 0xD0202020, 6.0)
    draw.add_text(pos, 0xFFFFFFFF, text)


# ---------------------------------------------------------------- Scene panel section


def draw_display_panel(state: AppState) -> bool:
    """Display options (tone map, clipping, AA, lines, fps; not part of the scene) and the
    camera's framing (field of view, fit aspect: scene fields, so it returns whether they
    were edited)."""
    if not imgui.collapsing_header("Display and presenter"):
        return False
    imgui.text("Tone map")
    for name in TONEMAPS:
        if same_line_if_fits(TONEMAP_LABELS[name], radio=True):
            imgui.same_line()
        if imgui.radio_button(TONEMAP_LABELS[name], state.view.tonemap == name):
            state.view.tonemap = name
    _, state.view.show_clipping = imgui.checkbox("Show clipped pixels (stripes)",
                                                 state.view.show_clipping)
    draw_antialias_choice(state)
    if state.view.presenter:  # off by default in front of a class
        _, state.view.fps_in_presenter = imgui.checkbox("fps readout",
                                                        state.view.fps_in_presenter)
    else:
        _, state.view.show_fps = imgui.checkbox("fps readout", state.view.show_fps)
    _, state.view.line_width = imgui.slider_float("line width", state.view.line_width, 0.0, 8.0,
                                             "%.1f px" if state.view.line_width > 0 else "auto")
    imgui.set_item_tooltip("0: by the presenter scale (>= 3 px in presenter mode)")
    _, state.view.show_gizmos = imgui.checkbox("Light gizmos", state.view.show_gizmos)
    _, state.view.hide_panels = imgui.checkbox("Viewport only (Tab)", state.view.hide_panels)
    _, state.view.fullscreen = imgui.checkbox("Fullscreen (F11)", state.view.fullscreen)
    # the camera's framing (scene fields): fov_y, and the narrowest aspect kept side to side
    from shadelab.ui.render_panel import float_slider

    cam = state.scene.camera
    edited = float_slider("field of view", cam, "fov_y", 10.0, 120.0, fmt="%.1f deg")
    edited |= float_slider("fit aspect", cam, "fit_aspect", 0.0, 3.0,
                           fmt="%.2f")
    return edited


def antialias_choices(limit: int) -> list[tuple[str, int, int]]:
    """(label, MSAA samples, supersampling factor) the GL allows; without multisampling
    (``limit`` 1) the 2x2 supersampling is the anti-aliasing offered."""
    choices = [("off", 1, 1)]
    choices += [(f"MSAA {n}x", n, 1) for n in (2, 4, 8) if n <= limit]
    choices.append(("2x2 SSAA", 1, 2))
    return choices


def draw_antialias_choice(state: AppState) -> None:
    """Anti-aliasing: off, MSAA 2 / 4 / 8 where the GL allows, or 2x2 supersampling."""
    imgui.text("Anti-aliasing")
    for label, samples, factor in antialias_choices(state.view.msaa_limit):
        if same_line_if_fits(label, radio=True):
            imgui.same_line()
        if imgui.radio_button(label, (state.view.msaa, state.view.antialias) == (samples, factor)):
            state.view.msaa, state.view.antialias = samples, factor


# ---------------------------------------------------------------- per frame


def end_frame(viewer: ViewportHost) -> None:
    """Fullscreen, panel visibility, dialogs, drops, stale overlays, panel focus."""
    from shadelab.ui import dialogs

    state = viewer.state
    apply_fullscreen(state)
    apply_layout(state)
    apply_panel_visibility(state)
    draw_presenter_viewport(viewer)
    dialogs.poll(state)
    dialogs.take_dropped(state)
    dialogs.draw_discard_question(state)
    drop_stale_overlays(state)
    if state.walk.focus_request and not state.view.hide_panels:
        # (on stage the request waits for Tab: focusing a hidden window would show it over
        # the stage)
        from shadelab.ui.layout import focus_windows

        focus_windows(hello_imgui.get_runner_params().docking_params.dockable_windows,
                      state.walk.focus_request)
        state.walk.focus_request = ""


_last_version: int = -1


def drop_stale_overlays(state: AppState) -> None:
    """Ray tree and radiosity solution belong to the scene the job rendered: once the scene
    (not just the camera) differs from it, they are cleared."""
    global _last_version
    if state.scene_version == _last_version:
        return
    _last_version = state.scene_version
    offline = state.offline
    if offline.scene is None or (offline.ray_tree is None and offline.radiosity_soup is None):
        return
    from shadelab.scene.preset import scene_to_dict

    now, then = scene_to_dict(state.scene), scene_to_dict(state.offline.scene)
    now.pop("camera", None)
    then.pop("camera", None)
    if now != then:
        state.offline.ray_tree = state.offline.ray_tree_pixel = None
        state.offline.radiosity_soup = None
        state.offline.show_radiosity = False
        state.offline.overlay_version += 1
        state.status = "the scene changed: ray tree and radiosity solution cleared (run again)"
