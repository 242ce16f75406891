"""Words drawn over the viewport image (imgui draw list): a figure's values under its objects,
object names on demand, the probe arrows' names at their heads, the probe's sum and GPU value
in the viewport's bottom-left corner, and the normal heat map's legend.

The positions come from :mod:`shadelab.lab.labels` and :mod:`shadelab.lab.overlays` (pure);
this module only measures text and draws it.
"""

from __future__ import annotations

import numpy as np
from imgui_bundle import imgui

from shadelab.lab import labels, overlays
from shadelab.lab.state import AppState

TEXT_COLOR = 0xFFFFFFFF
BOX_COLOR = 0xE0101010        # ImGui ABGR: a dark, nearly opaque plate behind the words
DIM_COLOR = 0xFFB0B0B0
OK_COLOR = 0xFF70E070
BAD_COLOR = 0xFF6060FF
PAD = 3.0

_cache: dict = {}
#: What the last frame drew, in screen pixels (GUI tests read it): the viewport's origin and
#: size, each plate's (text, x0, y0, x1, y1), the readout's and the legend's rectangles.
drawn: dict = {}


def _u32(rgb) -> int:
    r, g, b = (int(round(255 * min(max(float(c), 0.0), 1.0))) for c in rgb)
    return 0xFF000000 | (b << 16) | (g << 8) | r


def _plate(draw_list, x: float, y: float, text: str, color: int = TEXT_COLOR,
           centred: bool = True, bounds=None) -> None:
    """``text`` on a dark plate, its top at y, centred on x (or starting there), kept inside
    ``bounds`` (x0, y0, x1, y1) when given."""
    size = imgui.calc_text_size(text)
    x0 = x - 0.5 * size.x if centred else x
    if bounds is not None:
        x0 = min(max(x0, bounds[0] + PAD), bounds[2] - size.x - PAD)
        y = min(max(y, bounds[1] + PAD), bounds[3] - size.y - PAD)
    draw_list.add_rect_filled(imgui.ImVec2(x0 - PAD, y - PAD),
                              imgui.ImVec2(x0 + size.x + PAD, y + size.y + PAD), BOX_COLOR, 3.0)
    drawn.setdefault("plates", []).append((text, x0 - PAD, y - PAD, x0 + size.x + PAD,
                                           y + size.y + PAD))
    line = imgui.get_text_line_height()
    for k, part in enumerate(text.split("\n")):   # each line centred in the plate
        dx = 0.5 * (size.x - imgui.calc_text_size(part).x) if centred else 0.0
        draw_list.add_text(imgui.ImVec2(x0 + dx, y + k * line), color, part)


def object_texts(state: AppState) -> dict[int, str]:
    """What each object carries: its figure value (View: values) and its name (View: names)."""
    scene, view = state.scene, state.view
    values = labels.figure_values(scene) if view.show_values else {}
    names = labels.object_names(scene) if view.show_names else {}
    return {i: "\n".join(t for t in (values.get(i), names.get(i)) if t)
            for i in sorted(set(values) | set(names))}


def _measure(text: str) -> tuple[float, float]:
    """A label's plate in pixels (its text and the padding around it)."""
    size = imgui.calc_text_size(text)
    return size.x + 2 * PAD + 2, size.y + 2 * PAD + 2


def _object_labels(state: AppState, size: tuple[int, int]) -> list[labels.Label]:
    from shadelab.geometry.mesh import scene_meshes

    scene, view = state.scene, state.view
    line = imgui.get_text_line_height()
    key = (id(scene), state.scene_version, scene.version, size, view.show_values,
           view.show_names, line)
    if _cache.get("key") != key:
        texts = object_texts(state)
        placed = labels.place_labels(scene, scene_meshes(scene), size, texts, _measure) \
            if texts else []
        _cache.update(key=key, labels=placed)
    return _cache["labels"]


def draw(state: AppState, origin, size: tuple[int, int]) -> None:
    """Every label over the viewport image at ``origin`` (screen pixels), ``size`` large."""
    draw_list = imgui.get_window_draw_list()
    bounds = (origin.x, origin.y, origin.x + size[0], origin.y + size[1])
    drawn.clear()
    drawn.update(origin=(origin.x, origin.y), size=tuple(size))
    draw_list.push_clip_rect(imgui.ImVec2(bounds[0], bounds[1]),
                             imgui.ImVec2(bounds[2], bounds[3]), True)
    try:
        for label in _object_labels(state, size):
            _plate(draw_list, origin.x + label.anchor[0], origin.y + label.anchor[1] + PAD + 1,
                   label.text, bounds=bounds)
        result = state.probe.result
        if result is not None:
            _arrow_names(state, draw_list, origin, size, bounds)
            _probe_readout(state, draw_list, bounds)
        if state.view.show_normal_diff:
            _legend(state, draw_list, bounds)
    finally:
        draw_list.pop_clip_rect()


def _arrow_names(state: AppState, draw_list, origin, size, bounds) -> None:
    specs = overlays.probe_arrow_specs(state.probe.result, state.scene.camera,
                                       size[0] / max(size[1], 1))
    placed: list[tuple] = []
    for spec in specs:
        at = labels.to_pixels(state.scene, size, spec.tip)
        base = labels.to_pixels(state.scene, size, spec.start)
        if at is None or base is None:
            continue
        dx, dy = at[0] - base[0], at[1] - base[1]
        norm = np.hypot(dx, dy)
        if norm < 12.0:          # seen end-on (V points at the eye): beside the point
            dx, dy, norm = 1.0, 1.0, np.sqrt(2.0)
        text_size = imgui.calc_text_size(spec.name)
        # just past the head, along the arrow's screen direction; further along it while
        # the plate would cover a name placed before it
        for step in range(8):
            reach = 1.0 + 0.8 * step
            x = origin.x + at[0] + dx / norm * reach * (0.6 * text_size.x + PAD + 2)
            y = origin.y + at[1] + dy / norm * reach * (0.6 * text_size.y + PAD + 2) \
                - 0.5 * text_size.y
            rect = (x - 0.5 * text_size.x - PAD, y - PAD, x + 0.5 * text_size.x + PAD,
                    y + text_size.y + PAD)
            if not any(labels._overlap(rect, other) for other in placed):
                break
        placed.append(rect)
        _plate(draw_list, x, y, spec.name, _u32(spec.color), bounds=bounds)


def probe_lines(state: AppState) -> list[tuple[str, str, int]]:
    """The probe's readout rows (term, its RGB, colour): each term, their sum (the shading
    mode's I) and what the GPU drew."""
    result = state.probe.result
    terms = result.terms

    def rgb(v) -> str:
        return "  ".join(f"{float(c):.3f}" for c in np.asarray(v, dtype=np.float64).reshape(3))

    rows = []
    if np.any(terms.emission):
        rows.append(("Le", rgb(terms.emission), DIM_COLOR))
    rows.append(("Ia ka Od", rgb(terms.ambient), DIM_COLOR))
    diffuse = sum((t.diffuse for t in terms.lights), np.zeros(3))
    specular = sum((t.specular for t in terms.lights), np.zeros(3))
    rows.append(("+ diffuse", rgb(diffuse), DIM_COLOR))
    rows.append(("+ specular", rgb(specular), DIM_COLOR))
    rows.append((f"= I ({result.shading})", rgb(result.reference), TEXT_COLOR))
    if result.gpu is not None:
        err = float(np.max(np.abs(result.gpu - result.reference)))
        agree = err <= 1e-4 * max(1.0, float(np.max(np.abs(result.reference))))
        rows.append(("GPU drew", rgb(result.gpu) + ("  agrees" if agree else
                                                    f"  differs by {err:.2g}"),
                     OK_COLOR if agree else BAD_COLOR))
    return rows


def _probe_readout(state: AppState, draw_list, bounds) -> None:
    """Bottom-left corner of the viewport: never below the fold of a panel."""
    rows = probe_lines(state)
    line = imgui.get_text_line_height_with_spacing()
    gap = imgui.calc_text_size("  ").x
    first = max(imgui.calc_text_size(term).x for term, _, _ in rows) + gap
    width = first + max(imgui.calc_text_size(values).x for _, values, _ in rows)
    x, y = bounds[0] + 2 * PAD + 4, bounds[3] - len(rows) * line - 2 * PAD - 4
    draw_list.add_rect_filled(imgui.ImVec2(x - PAD - 2, y - PAD - 2),
                              imgui.ImVec2(x + width + PAD + 2, y + len(rows) * line + PAD),
                              BOX_COLOR, 4.0)
    drawn["readout"] = ([term for term, _, _ in rows],
                        (x - PAD - 2, y - PAD - 2, x + width + PAD + 2, y + len(rows) * line + PAD))
    for i, (term, values, color) in enumerate(rows):
        draw_list.add_text(imgui.ImVec2(x, y + i * line), color, term)
        draw_list.add_text(imgui.ImVec2(x + first, y + i * line), color, values)


def heat_scale(state: AppState) -> tuple[list, float]:
    """The heat map's per-mesh angles (degrees) and its full scale, cached on the geometry."""
    from shadelab.geometry.mesh import geometry_key, scene_meshes

    scene = state.scene
    modes = tuple(state.view.normal_diff_modes)
    key = (tuple(geometry_key(o, scene.base_dir) for o in scene.objects), modes)
    if _cache.get("heat_key") != key:
        meshes = scene_meshes(scene)
        degrees = overlays.normal_difference(meshes, *modes)
        top = max((float(d.max()) for d in degrees if len(d)), default=0.0)
        _cache.update(heat_key=key, heat=(degrees, overlays.heat_scale_max(top)))
    return _cache["heat"]


def _legend(state: AppState, draw_list, bounds) -> None:
    """A colour bar, 0 to full scale in degrees, in the viewport's bottom-right corner (the
    probe's readout has the bottom-left one)."""
    _, full = heat_scale(state)
    a, b = state.view.normal_diff_modes
    title = f"angle {a} vs {b}"
    line = imgui.get_text_line_height()
    width = max(imgui.calc_text_size(title).x, 9 * line)
    x = bounds[2] - width - 2 * PAD - 4
    y = bounds[3] - 3.4 * line - 2 * PAD - 4
    draw_list.add_rect_filled(imgui.ImVec2(x - PAD - 2, y - PAD - 2),
                              imgui.ImVec2(x + width + PAD + 2, y + 3.4 * line + PAD),
                              BOX_COLOR, 4.0)
    draw_list.add_text(imgui.ImVec2(x, y), TEXT_COLOR, title)
    top, bar = y + 1.2 * line, 0.9 * line
    drawn["legend"] = (title, full, (x, top, x + width, top + bar))
    steps = 32
    for k in range(steps):
        c0 = overlays.heat_color_srgb(k / steps)
        c1 = overlays.heat_color_srgb((k + 1) / steps)
        x0, x1 = x + width * k / steps, x + width * (k + 1) / steps
        draw_list.add_rect_filled_multi_color(
            imgui.ImVec2(x0, top), imgui.ImVec2(x1 + 0.5, top + bar),
            _u32(c0), _u32(c1), _u32(c1), _u32(c0))
    for k in range(3):   # 0, half and full scale
        text = f"{full * k / 2:.3g}\u00b0"
        tx = x + width * k / 2 - imgui.calc_text_size(text).x * k / 2
        draw_list.add_text(imgui.ImVec2(tx, top + bar + 2), TEXT_COLOR, text)
