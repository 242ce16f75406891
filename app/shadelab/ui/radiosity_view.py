"""Radiosity made visible (issue 10.4): the hemicube of a patch and the form-factor matrix.

The "Hemicube & F" window shows, for the shooting patch of the viewport's radiosity (or one
chosen with the slider), its hemicube unfolded as a cross: the top face in the middle, the
upper halves of the four side faces around it, each patch id in its own item-buffer color, and
next to it the same faces weighted by their delta form factors. The sums per face add up to
the patch's row of F. Below, F as an ImPlot heat map (block means when N > ``HEATMAP_MAX``)
and its row sums (1 in a closed scene).

The window asks the viewer's GL side for the work (``state.gpu`` requests, served by
:mod:`shadelab.ui.gpu_side` with :class:`shadelab.raster.hemicube.Hemicube` before the next
frame's panels): a patch's item images, and F's rows ``Hemicube.batch`` per frame, so the UI
never waits. Results are cached per geometry (the patches' key: a material or emission edit
keeps it) and patch. This module holds no GL object and imports no GL module.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

HEATMAP_MAX = 100        # heat-map cells per side shown (block means above)
FACES = ("top", "+t", "+b", "-t", "-b")
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


def cross_images(view: dict) -> tuple[np.ndarray, np.ndarray]:
    """(item-buffer colors, colors weighted by dF / max dF) as uint8 RGB crosses."""
    ids, dF = view["ids"], view["dF"]
    colors = id_colors(ids)
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


_views: dict[int, RadiosityView] = {}


FIRST_FRAMES = 2   # frames the viewer draws before this window builds its patches
ROWS, IMAGES = "hemicube_rows", "hemicube_images"   # the GPU requests (shadelab.ui.gpu_side)


def view_of(state) -> RadiosityView:
    return _views.setdefault(id(state), RadiosityView())


def geometry_key(scene) -> tuple:
    from shadelab.lab.pipeline_jobs import radiosity_key

    return (radiosity_key(scene), scene.radiosity.hemicube_resolution)


def ensure(state, view: RadiosityView | None = None) -> RadiosityView:
    """Patches for the scene's geometry (rebuilt when it changed; the GL side makes the
    hemicube of them on the first request)."""
    from shadelab.errors import ShadeLabError
    from shadelab.radiosity.patches import check_count, uniform_patches

    view = view or view_of(state)
    scene = state.scene
    key = geometry_key(scene)
    if key == view.key:
        return view
    view.key, view.views, view.shown, view.error = key, {}, None, ""
    view.res, view.batch = 0, 0
    try:
        check_count(scene.radiosity.patches, "radiosity.patches")
        view.patches = uniform_patches(scene, scene.radiosity.patches)
    except ShadeLabError as exc:
        view.patches, view.error = None, str(exc)
        return view
    n = len(view.patches)
    view.F, view.rows_done = np.zeros((n, n)), 0
    view.patch = min(view.patch, n - 1)
    view.id_soup = patch_id_soup(view.patches.polygons, scene.render.exposure)
    return view


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
        view.rows_done = int(result["rows"][-1]) + 1
        view.batch = result["batch"]
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


def draw_panel(state) -> bool:
    """The "Hemicube & F" window. Returns False (it edits no scene field)."""
    from imgui_bundle import imgui, implot

    from shadelab.ui.layout import same_line_if_fits

    if not state.gpu.attached:
        imgui.text("(no GL context yet)")
        return False
    if state.frame < FIRST_FRAMES:   # the scene's first frame comes first (about a second)
        imgui.text("building the patches ...")
        return False
    view = ensure(state)
    if view.error:
        imgui.text_colored(imgui.ImVec4(1.0, 0.35, 0.3, 1.0), view.error)
        return False
    n = len(view.patches)
    if n == 0:
        imgui.text_wrapped(empty_note(None, 0))
        return False
    step_rows(state, view)
    pv = state.view.pipeline_view
    shooter = None if pv is None else pv.stats.get("shooter_index")
    _, view.follow = imgui.checkbox("follow the shooting patch", view.follow)
    if same_line_if_fits("patch-id view (viewport)", radio=True):
        imgui.same_line()
    _, view.patch_ids = imgui.checkbox("patch-id view (viewport)", view.patch_ids)
    if view.follow and shooter is not None and 0 <= int(shooter) < n:
        view.patch = int(shooter)
    changed, value = imgui.slider_int("patch", view.patch, 0, n - 1)
    if changed:
        view.patch, view.follow = int(value), False
    i = view.patch
    hv = patch_view(state, view, i)
    if hv is not None and view.shown != (view.key, i):
        colors, weighted = cross_images(hv)
        state.gpu.upload("hemicube_ids", colors)
        state.gpu.upload("hemicube_dF", weighted)
        view.shown = (view.key, i)
    width = imgui.get_content_region_avail().x
    style = imgui.get_style()   # two images and their borders side by side, within the panel
    side = max(64.0, min(360.0, (width - style.item_spacing.x) / 2 - style.image_border_size))
    textures = [state.gpu.texture(name) for name in ("hemicube_ids", "hemicube_dF")]
    if view.shown is None or None in textures:   # the first hemicube is on its way
        imgui.text(f"rendering the hemicube of patch {i} ...")
        return False
    for k, tex in enumerate(textures):
        if k:
            imgui.same_line()
        imgui.image(imgui.ImTextureRef(tex.id), imgui.ImVec2(side, side))
    shown = view.shown[1]
    imgui.text_wrapped(f"patch {shown} of {n}: item buffer (left), x delta form factors (right); "
               f"hemicube {view.res}x{view.res}")
    hv = view.views.get(shown, hv)
    if hv is None:
        return False
    i = shown
    sums = hv["face_sums"]
    imgui.text_wrapped("  ".join(f"{k} {v:.4f}" for k, v in sums.items()))
    row_sum = float(view.F[i].sum()) if i < view.rows_done else None
    imgui.text_wrapped(f"sum over the 5 faces {hv['total']:.4f} (whole hemicube {hv['full']:.4f})"
               + (f" = row sum of F {row_sum:.4f}" if row_sum is not None else ""))
    _draw_matrix(view, i, imgui, implot)
    return False


def _draw_matrix(view: RadiosityView, i: int, imgui, implot) -> None:
    from shadelab.radiosity.formfactors import heatmap_data
    from shadelab.ui.layout import plot_size

    n = len(view.patches)
    if n == 0:
        imgui.text_wrapped(empty_note(None, 0))
        return
    if view.rows_done < n:
        imgui.text(f"form factors: {view.rows_done}/{n} rows")
        imgui.progress_bar(view.rows_done / n, imgui.ImVec2(-1, 0))
        return
    note = empty_note(view.F, view.rows_done)
    if note:
        imgui.text_wrapped(note)
        return
    data = heatmap_data(view.F)
    shown, k = block_means(data["matrix"])
    imgui.text_wrapped(f"form-factor matrix F ({n}x{n}"
               + (f", block means of {k}x{k}" if k > 1 else "") + f"), max {data['max']:.3g}")
    width = imgui.get_content_region_avail().x
    scale_width = 4.0 * imgui.get_font_size()       # the colormap scale's ticks grow with the font
    size = max(120.0, min(width - scale_width - imgui.get_style().item_spacing.x, 420.0))
    vmax = float(np.nanmax(shown)) if shown.size else 1.0
    implot.push_colormap(implot.Colormap_.viridis)
    if implot.begin_plot("##F", imgui.ImVec2(size, size), implot.Flags_.no_legend):
        flags = implot.AxisFlags_.lock | implot.AxisFlags_.no_grid_lines
        implot.setup_axes("j (receiving)", "i (shooting)", flags, flags | implot.AxisFlags_.invert)
        implot.setup_axes_limits(0, n, 0, n, imgui.Cond_.always)
        span = shown.shape[0] * k      # row i of F at y in [i, i + 1] (top: inverted axis)
        implot.plot_heatmap("F", np.ascontiguousarray(shown[::-1]), 0.0, vmax, "",
                            implot.Point(0, 0), implot.Point(span, span))
        implot.end_plot()
    imgui.same_line()
    implot.colormap_scale("##Fscale", 0.0, vmax, imgui.ImVec2(scale_width, size))
    implot.pop_colormap()
    sums = data["row_sums"]
    imgui.text_wrapped(f"row sums: min {sums.min():.4f}, mean {sums.mean():.4f}, "
                       f"max {sums.max():.4f} (1 in a closed scene); patch {i}: {sums[i]:.4f}")
    if implot.begin_plot("row sums of F", plot_size(9.0), implot.Flags_.no_legend):
        implot.setup_axes("patch i", "sum_j F_ij", implot.AxisFlags_.auto_fit,
                          implot.AxisFlags_.auto_fit)
        implot.plot_line("row sum", np.arange(n, dtype=np.float64), sums.astype(np.float64))
        implot.plot_inf_lines("patch", np.array([float(i)]))
        implot.end_plot()
