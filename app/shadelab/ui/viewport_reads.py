"""What the viewer reads back from its viewport's panes (GL thread): the probed pixel's GPU
value beside its CPU reference, and the viewport screenshot (the S key)."""

from __future__ import annotations

import time
from pathlib import Path

from shadelab.lab.probe import probe
from shadelab.lab.state import AppState
from shadelab.shading.codes import terms_mask


def update_probe(state: AppState, viewport, size: tuple[int, int],
                 display_size: tuple[int, int], samples: int = 1) -> None:
    """Recompute the probed pixel's terms (CPU reference) and read what the GPU drew.

    ``state.probe.pixel`` is in viewport pixels; the scene may be rendered at another
    resolution (render scale), so the pixel is mapped to the rendered image first. With
    ``samples`` > 1 (MSAA) the scene is drawn again single-sampled to read the pixel.
    """
    shown = state.probe.pixel
    if shown is None or not (0 <= shown[0] < display_size[0]
                             and 0 <= shown[1] < display_size[1]):
        state.probe.result = None
        state.probe.version += 1
        return  # (kept requested: the layout may still be settling)
    pixel = (min(int(shown[0] * size[0] / display_size[0]), size[0] - 1),
             min(int(shown[1] * size[1] / display_size[1]), size[1] - 1))
    state.probe.requested = False
    off = state.view.terms_off
    result = probe(state.scene, size, pixel, off=off)
    if result is not None and not state.offline.show_radiosity:
        key = "main"
        if samples > 1:  # a resolved edge pixel averages both sides: read 1 sample
            key = "probe"
            viewport.draw_scene(key, state.scene, size, state.scene.render.shading,
                                state.scene.render.specular, terms_off=terms_mask(off))
        result.gpu = viewport.read_pixel(key, pixel)
    state.probe.result = result
    state.probe.version += 1
    if result is None:
        state.status = f"pixel {pixel}: background (no surface)"


TOAST_S = 3.0  # seconds a saved screenshot is announced over the viewport


def write_viewport_screenshot(state: AppState, viewport, path: str) -> None:
    """The main pane as shown (with the legend burnt in when asked) as a PNG at ``path``;
    a failed write is one line in ``state.error``."""
    from PIL import Image

    from shadelab.lab.legend import burn_legend

    image = viewport.read_display("main")
    if state.view.legend_in_screenshot:
        image = burn_legend(image, state)
    try:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        Image.fromarray(image).save(path)
        state.status = f"screenshot {path}"
        state.toast = (f"saved {path}", time.monotonic() + TOAST_S)
    except (OSError, ValueError) as exc:
        state.error = f"screenshot '{path}': cannot write ({exc})"
