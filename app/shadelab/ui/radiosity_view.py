"""Radiosity made visible (issues 10.4, 19.1): the hemicube of a patch and the form-factor matrix.

The "Hemicube & F" window shows, for the shooting patch of the viewport's radiosity (or one
chosen with the slider), its hemicube unfolded as a cross: the top face in the middle, the
upper halves of the four side faces around it (labelled top, left, back, right, front; their
sums on the weighted cross), each patch id in its own item-buffer color, and next to it the
same faces weighted by their delta form factors. The sums per face add up to the patch's row of
F. Below, which form factors F holds, the convergence plot (unshot energy in % of the emitted
power against shots), F as an ImPlot heat map (block means when N > ``HEATMAP_MAX``) and its
row sums (1 in a closed scene). At its top: the radiosity pipeline's stepper (play / step mode
/ shoot next patch) and the ambient-estimate and patch-grid toggles.

One method: while the viewport's radiosity solves this window's patches, F holds the very rows
the solver shot with (the job sends them, ``stats["ff_rows"]``; the runner keeps them,
:attr:`shadelab.lab.jobs.JobRunner.rows`) and the window says which method made them (the
lesson's step uses the hemicube, so the picture is how each row was made). Otherwise the window
computes F itself with the GL hemicube, ``Hemicube.batch`` rows per frame. Its GL work goes
through ``state.gpu`` (:mod:`shadelab.ui.gpu_side`, before the next frame's panels): a patch's
item images, and those rows, so the UI never waits. Per frame the window does no work
proportional to the patches: new rows are copied as they arrive, the heat map's data is rebuilt
at most every ``MATRIX_EVERY_S`` while rows arrive, and a followed shooter's hemicube changes at
most every ``FOLLOW_S`` while shots stream. This module holds no GL object and imports no GL
module.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

HEATMAP_MAX = 100        # heat-map cells per side shown (block means above)
# the five faces as the unfolded cross shows them: top (along the normal) in the middle, the
# sides looking along +t (left), +b (back, above), -t (right), -b (front, below)
FACES = ("top", "left", "back", "right", "front")
NOTHING = (18, 18, 24)   # item-buffer color of "no patch"


# ---------------------------------------------------------------- numpy helpers


def id_colors(ids: np.ndarray) -> np.ndarray:
    """Distinct uint8 RGB per patch id (golden-ratio hues, three brightness bands); -1 and
    below: :data:`NOTHING`."""
    ids = np.asarray(ids)
    k = np.maximum(ids, 0).astype(np.float64)
    h = (k * 0.6180339887498949) % 1.0
    v = 1.0 - 0.25 * (k % 3)
    s = 0.55 + 0.15 * ((k // 3) % 3)
    i = np.floor(h * 6.0)
    f = h * 6.0 - i
    p, q, t = v * (1 - s), v * (1 - s * f), v * (1 - s * (1 - f))
    i = i.astype(int) % 6
    r = np.choose(i, [v, q, p, p, t, v])
    g = np.choose(i, [t, v, v, q, p, p])
    b = np.choose(i, [p, p, t, v, v, q])
    rgb = (np.stack([r, g, b], -1) * 255 + 0.5).astype(np.uint8)
    rgb[ids < 0] = NOTHING
    return rgb


def unfold(top: np.ndarray, sides: list, fill=-2) -> np.ndarray:
    """The hemicube's five faces as a (2 res, 2 res) cross: ``top`` (res, res) in the middle,
    side f (res/2, res; row 0 nearest the normal) on the edge it shares with the top face, so
    the picture is continuous across every seam. Outside the cross: ``fill``.

    Top face: columns run along -t, rows along -b (row 0 at +b); side faces look along
    +t, +b, -t, -b (see :meth:`shadelab.raster.hemicube.Hemicube._faces`)."""
    res = top.shape[0]
    h = res // 2
    out = np.full((2 * res, 2 * res) + top.shape[2:], fill, dtype=np.result_type(top, fill))
    out[h:h + res, h:h + res] = top
    pos_t, pos_b, neg_t, neg_b = sides
    out[h:h + res, :h] = np.swapaxes(pos_t[::-1], 0, 1)        # +t: left of the top face
    out[:h, h:h + res] = pos_b[::-1, ::-1]                      # +b: above
    out[h:h + res, h + res:] = np.swapaxes(neg_t[:, ::-1], 0, 1)  # -t: right
    out[h + res:, h:h + res] = neg_b                            # -b: below
    return out


def hemicube_view(images: dict) -> dict:
    """What the window shows of :meth:`Hemicube.item_images`: the unfolded ``ids`` and
    ``dF`` crosses, ``face_sums`` (delta form factors of the pixels that see a patch, per
    face), their ``total`` and ``row`` (the per-patch sums over all five faces)."""
    top, sides = images["top"], images["sides"]
    top_df, side_df = images["top_dF"], images["side_dF"]
    ids = unfold(top, sides)
    dF = unfold(top_df, [side_df] * 4, fill=0.0)
    sums = [float(top_df[top >= 0].sum())] + [float(side_df[s >= 0].sum()) for s in sides]
    n = len(images["row"])
    seen = ids >= 0
    row = np.bincount(ids[seen].ravel(), weights=dF[seen].ravel(), minlength=n)[:n]
    return {"ids": ids, "dF": dF, "face_sums": dict(zip(FACES, sums, strict=True)),
            "total": float(sum(sums)), "row": row, "full": float(dF.sum())}


def cross_images(view: dict, palette: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(item-buffer colors, colors weighted by dF / max dF) as uint8 RGB crosses;
    ``palette``: :func:`id_colors` of 0..N-1, computed once per patch set (a lookup per
    pixel instead of the colour formula)."""
    ids, dF = view["ids"], view["dF"]
    if palette is None:
        colors = id_colors(ids)
    else:
        table = np.concatenate([palette, np.asarray([NOTHING, NOTHING], np.uint8)])
        colors = table[np.where(ids >= 0, ids, len(palette))]
    colors[ids == -2] = 0
    weight = dF / max(float(dF.max()), 1e-300)
    weighted = (colors * weight[..., None] ** 0.5).astype(np.uint8)  # sqrt: edges visible
    return colors, weighted


def block_means(F: np.ndarray, most: int = HEATMAP_MAX) -> tuple[np.ndarray, int]:
    """F as block means of k x k (k = ceil(N / most)); k = 1: F itself."""
    n = F.shape[0]
    k = max(1, -(-n // most))
    if k == 1:
        return F, 1
    m = -(-n // k)
    padded = np.full((m * k, m * k), np.nan)
    padded[:n, :n] = F
    return np.nanmean(padded.reshape(m, k, m, k), axis=(1, 3)), k


def empty_note(F: np.ndarray | None, rows_done: int) -> str:
    """What the window says instead of an all-zero F ("" when F has something to show): no
    patches, or every form factor zero (no patch sees another: no closed surfaces facing
    each other, e.g. a scene made for the raster pipelines, without radiosity settings)."""
    if F is None or F.size == 0:
        return "no patches in this scene: nothing to show"
    if rows_done >= F.shape[0] and not np.any(F):
        return ("every form factor is 0: no patch sees another in this scene, so F has "
                "nothing to show (try a radiosity preset, e.g. radiosity-box)")
    return ""


def patch_id_soup(polygons: np.ndarray, exposure: float = 1.0) -> np.ndarray:
    """(6N, 6) float32 triangles, each patch in its item color (linear radiance that the
    viewport's exposure and sRGB encoding turn back into that color)."""
    n = len(polygons)
    srgb = id_colors(np.arange(n)) / 255.0
    linear = np.where(srgb <= 0.04045, srgb / 12.92, ((srgb + 0.055) / 1.055) ** 2.4)
    linear = linear / max(float(exposure), 1e-12)
    tri = np.concatenate([polygons[:, [0, 1, 2]], polygons[:, [0, 2, 3]]], 1).reshape(-1, 3)
    out = np.empty((6 * n, 6), np.float32)
    out[:, :3], out[:, 3:] = tri, np.repeat(linear, 6, axis=0)
    return out


# ---------------------------------------------------------------- the window's state


@dataclass
class RadiosityView:
    key: object = None
    patches: object = None
    res: int = 0                         # hemicube resolution (the GL side's, once known)
    batch: int = 0                       # rows of F per request (one atlas read-back)
    F: np.ndarray | None = None
    rows_done: int = 0
    patch: int = 0
    follow: bool = True                  # show the viewport's shooting patch
    patch_ids: bool = False              # viewport: patches in their item colors
    views: dict = field(default_factory=dict)   # patch -> hemicube_view(...)
    shown: object = None                 # (key, patch) on the textures now
    error: str = ""
    id_soup: np.ndarray | None = None
    source: object = None                # "window" (own GL rows) or id(the job's rows dict)
    known: np.ndarray | None = None      # rows of F known (the solver's: its shooters')
    f_version: int = 0                   # bumps when rows arrive (the heat map's cache key)
    matrix: dict | None = None           # matrix_data's cache
    followed_at: float = 0.0             # when the followed shooter last changed the patch
    label_rects: list = field(default_factory=list)   # face labels drawn (text, x0, y0, x1, y1)
    palette: np.ndarray | None = None    # id_colors of the patches (the crosses' lookup)
    job_key: tuple = (None, None)        # (the viewport job's scene, its geometry_key)
    building: object = None              # the thread making the patches (ensure)
    built: dict = field(default_factory=dict)   # its result: "patches" or "error"


_views: dict[int, RadiosityView] = {}


FIRST_FRAMES = 2   # frames the viewer draws before this window builds its patches
ROWS, IMAGES = "hemicube_rows", "hemicube_images"   # the GPU requests (shadelab.ui.gpu_side)


def view_of(state) -> RadiosityView:
    return _views.setdefault(id(state), RadiosityView())


_KEYS: dict = {}   # (edit key of objects and radiosity settings, base_dir) -> geometry_key


def geometry_key(scene) -> tuple:
    """What the patches depend on. Asked in every frame: the full key (a repr of every
    object) is built once per edit of the objects or radiosity settings (a copy of a scene
    shares its original's edit key, so the viewport job's scene finds it too)."""
    from shadelab.lab.pipeline_jobs import radiosity_key

    edit = (scene.edit_key("objects", "radiosity"), scene.base_dir)
    key = _KEYS.get(edit)
    if key is None:
        if len(_KEYS) > 8:
            _KEYS.clear()
        key = _KEYS[edit] = (radiosity_key(scene), scene.radiosity.hemicube_resolution)
    return key


def ensure(state, view: RadiosityView | None = None, wait: bool = False) -> RadiosityView:
    """Patches for the scene's geometry, rebuilt when it changed: in a thread (a 400-patch
    grid took ~100 ms, a stalled frame of the slide); ``view.patches`` is None until they are
    there (``wait``: build them now). The GL side makes their hemicube on the first request."""
    import threading

    from shadelab.scene.preset import clone_scene

    view = view or view_of(state)
    scene = state.scene
    key = geometry_key(scene)
    if key != view.key:
        view.key, view.views, view.shown, view.error = key, {}, None, ""
        view.res, view.batch, view.patches, view.built = 0, 0, None, {}
        view.id_soup = None
        copy, result = clone_scene(scene), view.built
        view.building = threading.Thread(target=_build_patches, args=(copy, result),
                                         daemon=True, name="shadelab-hemicube-patches")
        view.building.start()
    if view.building is not None and (wait or not view.building.is_alive()):
        view.building.join()
        view.building = None
        _take_patches(view, view.built, scene.render.exposure)
    return view


def _build_patches(scene, result: dict) -> None:
    from shadelab.errors import ShadeLabError
    from shadelab.radiosity.patches import check_count, uniform_patches

    try:
        check_count(scene.radiosity.patches, "radiosity.patches")
        result["patches"] = uniform_patches(scene, scene.radiosity.patches)
    except ShadeLabError as exc:
        result["error"] = str(exc)
    except Exception as exc:   # shown in the window; the session goes on
        result["error"] = f"{type(exc).__name__}: {exc}"


def _take_patches(view: RadiosityView, result: dict, exposure: float) -> None:
    if "error" in result or "patches" not in result:
        view.patches, view.error = None, result.get("error", "no patches")
        return
    view.patches = result["patches"]
    n = len(view.patches)
    view.F, view.rows_done, view.known, view.source = np.zeros((n, n)), 0, np.zeros(n, bool), None
    view.matrix = None
    view.patch = min(view.patch, max(n - 1, 0))
    view.id_soup = patch_id_soup(view.patches.polygons, exposure)
    view.palette = id_colors(np.arange(n))


def _ask(state, view: RadiosityView, what: str, **args) -> None:
    state.gpu.request(what, what, key=view.key, patches=view.patches,
                      resolution=state.scene.radiosity.hemicube_resolution, **args)


def _result(state, view: RadiosityView, what: str) -> dict | None:
    """The GL side's answer to ``what`` for this geometry (an error goes to ``view.error``)."""
    if what in state.gpu.errors:
        view.error = state.gpu.errors.pop(what)
    result = state.gpu.take(what)
    if result is None or result["key"] != view.key:
        return None
    view.res = result["res"]
    return result


def step_rows(state, view: RadiosityView) -> None:
    """Take the rows of F the GL side computed last frame; ask for the next batch."""
    result = _result(state, view, ROWS)
    if result is not None and result["rows"].size and int(result["rows"][0]) == view.rows_done:
        view.F[result["rows"]] = result["values"]
        view.known[result["rows"]] = True
        view.rows_done = int(result["rows"][-1]) + 1
        view.batch = result["batch"]
        view.f_version += 1
    if view.rows_done < len(view.patches) and not state.gpu.pending(ROWS):
        _ask(state, view, ROWS, start=view.rows_done)


def patch_view(state, view: RadiosityView, i: int) -> dict | None:
    """:func:`hemicube_view` of patch ``i`` (None while the GL side renders its hemicube)."""
    result = _result(state, view, IMAGES)
    if result is not None:
        if len(view.views) > 64:
            view.views.clear()
        view.views[result["patch"]] = hemicube_view(result["images"])
    if i not in view.views and not state.gpu.pending(IMAGES):
        _ask(state, view, IMAGES, patch=i)
    return view.views.get(i)


def viewport_soup(state, soup):
    """The radiosity pipeline's triangles, or the patch-id view when it is on (pipelines
    hook)."""
    view = _views.get(id(state))
    if view is None or not view.patch_ids or view.id_soup is None \
            or view.key != geometry_key(state.scene):
        return soup
    return view.id_soup


def solver_rows(state, view: RadiosityView) -> tuple[dict, dict] | None:
    """(rows, stats) of the viewport's radiosity job when it solves this window's patches:
    the rows of F the solver shot with (:attr:`shadelab.lab.jobs.JobRunner.rows`), so the
    window shows those and computes none of its own."""
    pv = state.view.pipeline_view
    if pv is None or pv.runner is None or pv.name != "radiosity" or pv.job_scene is None:
        return None
    if view.job_key[0] is not pv.job_scene:      # once per job, not in every frame
        view.job_key = (pv.job_scene, geometry_key(pv.job_scene))
    if view.job_key[1] != view.key:
        return None
    return pv.runner.rows, pv.stats


def take_solver_rows(view: RadiosityView, rows: dict) -> None:
    """Copy the rows not yet in ``view.F`` (a new job's dict starts the count again)."""
    n = len(view.patches)
    if view.source != id(rows):
        view.source, view.known = id(rows), np.zeros(n, bool)
        view.F, view.rows_done = np.zeros((n, n)), 0
    if len(rows) == view.rows_done:
        return
    for i, values in list(rows.items()):
        if 0 <= i < n and not view.known[i] and len(values) == n:
            view.F[i] = values
            view.known[i] = True
    view.rows_done = int(view.known.sum())
    view.f_version += 1


FOLLOW_S = 0.4   # while shots stream, the followed hemicube changes at most this often


def draw_panel(state) -> bool:
    """The "Hemicube & F" window. Returns True when it edited the scene (the ambient
    toggle)."""
    from imgui_bundle import imgui

    from shadelab.ui.layout import same_line_if_fits

    if not state.gpu.attached:
        imgui.text("(no GL context yet)")
        return False
    if state.frame < FIRST_FRAMES:   # the scene's first frame comes first (about a second)
        imgui.text("building the patches ...")
        return False
    edited = draw_controls(state)
    view = ensure(state)
    if view.error:
        imgui.text_colored(imgui.ImVec4(1.0, 0.35, 0.3, 1.0), view.error)
        return edited
    if view.patches is None:
        imgui.text("building the patches ...")
        return edited
    n = len(view.patches)
    if n == 0:
        imgui.text_wrapped(empty_note(None, 0))
        return edited
    solver = solver_rows(state, view)
    if solver is not None:
        take_solver_rows(view, solver[0])
    else:
        if view.source != "window":
            view.source, view.F, view.rows_done = "window", np.zeros((n, n)), 0
            view.known = np.zeros(n, bool)
        step_rows(state, view)
    pv = state.view.pipeline_view
    shooter = None if pv is None or solver is None else pv.stats.get("shooter_index")
    _, view.follow = imgui.checkbox("follow the shooting patch", view.follow)
    if same_line_if_fits("patch-id view (viewport)", radio=True):
        imgui.same_line()
    _, view.patch_ids = imgui.checkbox("patch-id view (viewport)", view.patch_ids)
    if view.follow and shooter is not None and 0 <= int(shooter) < n \
            and int(shooter) != view.patch:
        streaming = pv.runner is not None and pv.runner.running and not pv.step_mode
        now = time.perf_counter()
        if not streaming or now - view.followed_at >= FOLLOW_S:
            view.patch, view.followed_at = int(shooter), now
    changed, value = imgui.slider_int("patch", view.patch, 0, n - 1)
    if changed:
        view.patch, view.follow = int(value), False
    i = view.patch
    hv = patch_view(state, view, i)
    if hv is not None and view.shown != (view.key, i):
        colors, weighted = cross_images(hv, view.palette)
        state.gpu.upload("hemicube_ids", colors)
        state.gpu.upload("hemicube_dF", weighted)
        view.shown = (view.key, i)
    width = imgui.get_content_region_avail().x
    style = imgui.get_style()   # two images and their borders side by side, within the panel
    side = max(64.0, min(360.0, (width - style.item_spacing.x) / 2 - style.image_border_size))
    textures = [state.gpu.texture(name) for name in ("hemicube_ids", "hemicube_dF")]
    if view.shown is None or None in textures:   # the first hemicube is on its way
        imgui.text(f"rendering the hemicube of patch {i} ...")
        return edited
    shown = view.shown[1]
    hv = view.views.get(shown)
    view.label_rects = []
    for k, tex in enumerate(textures):
        if k:
            imgui.same_line()
        corner = imgui.get_cursor_screen_pos()
        imgui.image(imgui.ImTextureRef(tex.id), imgui.ImVec2(side, side))
        if hv is not None:
            _label_faces(view, imgui, corner, side,
                         FACES if k == 0 else [f"{v:.3f}" for v in hv["face_sums"].values()])
    on_way = "" if shown == i else f" (its hemicube on the way; shown: patch {shown})"
    imgui.text_wrapped(f"patch {i} of {n} (0 to {n - 1}){on_way}: item buffer (left), "
                       f"x delta form factors (right); hemicube {view.res}x{view.res}")
    if hv is None:
        return edited
    sums = hv["face_sums"]
    imgui.text_wrapped("  ".join(f"{k} {v:.4f}" for k, v in sums.items()))
    row_sum = float(view.F[shown].sum()) if view.known[shown] else None
    imgui.text_wrapped(f"sum over the 5 faces {hv['total']:.4f} (whole hemicube {hv['full']:.4f})"
                       + (f"; row sum of F {row_sum:.4f}" if row_sum is not None else ""))
    _draw_method(state, view, solver, imgui)
    _draw_convergence(state, imgui)
    _draw_matrix(view, shown, imgui)
    return edited


def draw_controls(state) -> bool:
    """Above the hemicube, visible at 1024x768 in presenter mode: the radiosity pipeline's
    stepper (play / step mode / shoot next patch), the ambient-estimate and patch-grid
    toggles. True when the scene was edited (ambient)."""
    from imgui_bundle import imgui

    from shadelab.ui import pipelines
    from shadelab.ui.layout import same_line_if_fits

    if pipelines.current(state) != "radiosity":
        if imgui.small_button("Show radiosity in the viewport"):
            pipelines.set_pipeline(state, "radiosity")
        return False
    draw_radiosity_stepper(pipelines.view_of(state))
    settings = state.scene.radiosity
    changed, value = imgui.checkbox("ambient estimate", settings.ambient)
    edited = False
    if changed:
        settings.ambient = bool(value)
        state.mark_edited()
        edited = True
    if same_line_if_fits("patch grid", radio=True):
        imgui.same_line()
    _, state.view.radiosity_patches = imgui.checkbox("patch grid", state.view.radiosity_patches)
    return edited


def draw_radiosity_stepper(view) -> None:
    """Play (shots stream) or step: one shot per press, the shooting patch highlighted
    (``view``: the viewport's PipelineView; here and in the Algorithms window)."""
    from imgui_bundle import imgui

    from shadelab.ui.layout import same_line_if_fits

    imgui.text("Progressive refinement:")
    if same_line_if_fits("Play" if view.step_mode else "Restart"):
        imgui.same_line()
    if imgui.small_button("Play" if view.step_mode else "Restart"):
        view.step_mode, view.key = False, None   # a new job, shots streaming
    if not view.step_mode:
        if same_line_if_fits("Step mode"):
            imgui.same_line()
        if imgui.small_button("Step mode"):
            view.step_mode, view.key = True, None
        return
    if same_line_if_fits("Shoot next patch"):
        imgui.same_line()
    gate = view.stats.get("gate")
    imgui.begin_disabled(gate is None or not view.runner.running)
    if imgui.small_button("Shoot next patch"):
        gate.step()
    imgui.end_disabled()


FACE_CENTRES = ((0.5, 0.5), (0.125, 0.5), (0.5, 0.125), (0.875, 0.5), (0.5, 0.875))


def face_label_positions(side: float, texts, measure) -> list[tuple[float, float, str]]:
    """(x, y, text) of each face's label, its box centred on the face in the unfolded cross
    (:func:`unfold`: top in the middle, left = +t, back = +b above, right = -t, front = -b
    below) of an image ``side`` pixels wide; ``measure(text) -> (w, h)``."""
    out = []
    for (u, v), text in zip(FACE_CENTRES, texts, strict=True):
        w, h = measure(text)
        out.append((u * side - w / 2.0, v * side - h / 2.0, text))
    return out


def _label_faces(view: RadiosityView, imgui, corner, side: float, texts) -> None:
    draw_list = imgui.get_window_draw_list()
    size = 0.8 * imgui.get_font_size()
    font = imgui.get_font()

    def measure(text):
        w = imgui.calc_text_size(text).x * 0.8
        return w, size

    for x, y, text in face_label_positions(side, texts, measure):
        w, h = measure(text)
        a = imgui.ImVec2(corner.x + x - 2, corner.y + y - 1)
        b = imgui.ImVec2(corner.x + x + w + 2, corner.y + y + h + 1)
        draw_list.add_rect_filled(a, b, 0xC0000000)
        draw_list.add_text(font, size, imgui.ImVec2(corner.x + x, corner.y + y), 0xFFFFFFFF,
                           text)
        view.label_rects.append((text, a.x, a.y, b.x, b.y))


def method_line(view: RadiosityView, solver, hv_total: float | None = None) -> str:
    """Which form factors F holds and whose they are (one line for the window)."""
    n = len(view.patches)
    if solver is None:
        return (f"F: hemicube {view.res}x{view.res}, this window's own (the viewport's "
                f"radiosity does not solve these patches now): {view.rows_done} of {n} rows")
    stats = solver[1]
    label = stats.get("form_factors_label") or stats.get("form_factors") or "?"
    line = (f"F: {label}, the rows the solver shot with: {view.rows_done} of {n} known "
            f"(progressive refinement computes only its shooters' rows)")
    if stats.get("form_factors") not in (None, "hemicube"):
        line += ("; the hemicube above is the GPU method's picture of the same row"
                 + (f" (its sum {hv_total:.4f})" if hv_total is not None else ""))
    if stats.get("form_factors_note"):
        line += f"; {stats['form_factors_note']}"
    return line


def _draw_method(state, view: RadiosityView, solver, imgui) -> None:
    shown = view.shown[1] if view.shown else None
    hv = view.views.get(shown) if shown is not None else None
    imgui.text_wrapped(method_line(view, solver, hv["total"] if hv else None))


def _draw_convergence(state, imgui) -> None:
    """Unshot energy against shots (progressive refinement), log scale, axes with units."""
    from imgui_bundle import implot

    from shadelab.ui.layout import plot_size

    pv = state.view.pipeline_view
    history = {} if pv is None or pv.name != "radiosity" else pv.history
    x, y, label = convergence_series(history)
    if x is None:
        return
    title = "unshot energy, % of emitted" if "unshot" in label else "residual, % of |E|"
    if implot.begin_plot(f"{title}##convergence", plot_size(9.0), implot.Flags_.no_legend):
        implot.setup_axes("shots" if "unshot" in label else "iterations", axis_label(label),
                          implot.AxisFlags_.auto_fit, implot.AxisFlags_.auto_fit)
        implot.setup_axis_scale(implot.ImAxis_.y1, implot.Scale_.log10)
        if len(x):
            implot.plot_line(label, x, y)
        implot.end_plot()


def axis_label(label: str) -> str:
    """The y axis's short label (the plot's title says the rest): presenter fonts cut a long
    vertical label off."""
    return "unshot (%)" if "unshot" in label else "residual (%)"


def convergence_series(history: dict):
    """(shots, values, y-axis label) of a radiosity job's history: progressive refinement's
    unshot energy in % of the emitted power, else the iterative solvers' relative residual
    in %; (None, None, "") without a history."""
    if not history or not history.get("iteration"):
        return None, None, ""
    x = np.asarray(history["iteration"], np.float64)
    unshot = np.asarray(history["unshot"], np.float64)
    residual = np.asarray(history["residual"], np.float64)
    if np.isnan(residual).all():
        y, label = 100.0 * unshot, "unshot energy (% of emitted)"
    else:
        y, label = 100.0 * residual, "residual |E + rho F B - B| / |E| (%)"
    keep = np.isfinite(y) & (y > 0)
    return x[keep], y[keep], label


def _draw_matrix(view: RadiosityView, i: int, imgui) -> None:
    from imgui_bundle import implot

    from shadelab.ui.layout import plot_size

    n = len(view.patches)
    if n == 0:
        imgui.text_wrapped(empty_note(None, 0))
        return
    if view.source == "window" and view.rows_done < n:
        imgui.text(f"form factors: {view.rows_done}/{n} rows")
        imgui.progress_bar(view.rows_done / n, imgui.ImVec2(-1, 0))
        return
    if view.rows_done == 0:
        return
    note = empty_note(view.F, view.rows_done)
    if note:
        imgui.text_wrapped(note)
        return
    data = matrix_data(view)
    shown, k, vmax = data["shown"], data["k"], data["vmax"]
    imgui.text_wrapped(f"form-factor matrix F ({n}x{n}"
                       + (f", block means of {k}x{k}" if k > 1 else "")
                       + f"), max {data['max']:.3g}"
                       + ("" if view.rows_done == n else "; rows not known yet are 0"))
    width = imgui.get_content_region_avail().x
    scale_width = 4.0 * imgui.get_font_size()       # the colormap scale's ticks grow with the font
    size = max(120.0, min(width - scale_width - imgui.get_style().item_spacing.x, 420.0))
    implot.push_colormap(implot.Colormap_.viridis)
    if implot.begin_plot("##F", imgui.ImVec2(size, size), implot.Flags_.no_legend):
        flags = implot.AxisFlags_.lock | implot.AxisFlags_.no_grid_lines
        implot.setup_axes("j (receiving)", "i (shooting)", flags, flags | implot.AxisFlags_.invert)
        implot.setup_axes_limits(0, n, 0, n, imgui.Cond_.always)
        span = shown.shape[0] * k      # row i of F at y in [i, i + 1] (top: inverted axis)
        implot.plot_heatmap("F", data["flipped"], 0.0, vmax, "",
                            implot.Point(0, 0), implot.Point(span, span))
        implot.end_plot()
    imgui.same_line()
    implot.colormap_scale("##Fscale", 0.0, vmax, imgui.ImVec2(scale_width, size))
    implot.pop_colormap()
    sums = data["row_sums"]
    known = view.known if view.known is not None else np.ones(n, bool)
    if known.any():
        s = sums[known]
        imgui.text_wrapped(f"row sums (known rows): min {s.min():.4f}, mean {s.mean():.4f}, "
                           f"max {s.max():.4f} (1 in a closed scene)"
                           + (f"; patch {i}: {sums[i]:.4f}" if known[i] else ""))
    if implot.begin_plot("row sums of F", plot_size(9.0), implot.Flags_.no_legend):
        implot.setup_axes("patch i", "sum_j F_ij", implot.AxisFlags_.auto_fit,
                          implot.AxisFlags_.auto_fit)
        idx = np.flatnonzero(known).astype(np.float64)
        implot.plot_scatter("row sum", idx, sums[known].astype(np.float64))
        implot.plot_inf_lines("patch", np.array([float(i)]))
        implot.end_plot()


MATRIX_EVERY_S = 0.5   # while rows stream in, the heat map's data is rebuilt at most this often


def matrix_data(view: RadiosityView) -> dict:
    """The heat map's block means, its maximum and F's row sums, rebuilt when F changed (at
    most every ``MATRIX_EVERY_S`` while rows arrive), not in every frame. (The numbers of
    :func:`shadelab.radiosity.formfactors.heatmap_data`, without importing that numba module
    on the UI thread: its first import stalled a frame for seconds.)"""
    cached = view.matrix
    now = time.perf_counter()
    if cached is not None and cached["key"] == (view.key, view.source):
        if cached["version"] == view.f_version or now - cached["at"] < MATRIX_EVERY_S:
            return cached
    data = {"row_sums": view.F.sum(axis=1), "max": float(view.F.max(initial=0.0))}
    shown, k = block_means(view.F)
    view.matrix = {"key": (view.key, view.source), "version": view.f_version, "at": now,
                   "shown": shown, "k": k, "max": data["max"], "row_sums": data["row_sums"],
                   "vmax": float(np.nanmax(shown)) if shown.size else 1.0,
                   "flipped": np.ascontiguousarray(shown[::-1])}
    return view.matrix
