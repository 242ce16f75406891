"""Small layout helpers shared by the panels, the presenter mode and the dock windows (no
state, no GL): they sit below every other ui module, so none of them import each other back."""

from __future__ import annotations

from imgui_bundle import imgui


def same_line_if_fits(label: str, radio: bool = False) -> bool:
    """True when a button (or, ``radio``, a radio button / checkbox) labelled ``label`` fits
    on the line after the last item; else it goes on the next line (narrow panels wrap)."""
    style = imgui.get_style()
    text = imgui.calc_text_size(label.split("##")[0]).x
    needed = text + style.item_spacing.x + (
        imgui.get_frame_height() + style.item_inner_spacing.x if radio
        else 2 * style.frame_padding.x)
    last = imgui.get_item_rect_max().x
    # The cursor is at the start of the next line: its x plus the space left is the right edge.
    right = imgui.get_cursor_screen_pos().x + imgui.get_content_region_avail().x
    return last + needed <= right


def focus_windows(windows, focus: str) -> list[str]:
    """Bring the named dock windows to the front: ``focus`` is a comma-separated list of label
    prefixes (or words of a label: 'gallery' finds 'Failure gallery'); one window per dock
    space. Returns the labels focused."""
    chosen: dict[str, object] = {}
    for wanted in (w.strip().lower() for w in focus.split(",") if w.strip()):
        match = [w for w in windows if w.label.lower().startswith(wanted)] \
            or [w for w in windows if wanted in w.label.lower()]
        if match:
            chosen[match[0].dock_space_name] = match[0]
    for window in windows:
        if window.dock_space_name in chosen:
            window.focus_window_at_next_frame = window is chosen[window.dock_space_name]
    return [w.label for w in chosen.values()]

def plot_size(height_lines: float, width: float = -1.0):
    """An ImPlot frame ``height_lines`` text lines high (full width by default): plots grow
    with the font, so presenter mode's large labels and ticks keep room for the curve."""
    return imgui.ImVec2(width, height_lines * imgui.get_text_line_height_with_spacing())


LABEL_SHARE = 0.42   # share of a panel's width its widgets leave to the labels on their right


def push_label_room() -> None:
    """Widgets in the panel about to be drawn leave ``LABEL_SHARE`` of its width to their
    labels (ImGui's default leaves 35 %, and presenter fonts cut labels off at 1024x768).
    Pair with ``imgui.pop_item_width()``."""
    imgui.push_item_width(-LABEL_SHARE * imgui.get_content_region_avail().x)
