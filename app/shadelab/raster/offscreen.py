"""Headless rendering on the shared EGL context: Scene -> linear float image."""

from __future__ import annotations

import numpy as np

from shadelab.gl.context import headless_context
from shadelab.gl.target import RenderTarget
from shadelab.raster.renderer import Renderer
from shadelab.scene.model import Scene

_RENDERER: Renderer | None = None
_TARGETS: dict[tuple[int, int], RenderTarget] = {}


def shared_renderer() -> Renderer:
    """One Renderer on the process's headless context."""
    global _RENDERER
    if _RENDERER is None:
        _RENDERER = Renderer(headless_context())
    return _RENDERER


def shared_target(size: tuple[int, int]) -> RenderTarget:
    if size not in _TARGETS:
        _TARGETS[size] = RenderTarget(headless_context(), size)
    return _TARGETS[size]


def render_image(scene: Scene, size: tuple[int, int], shading: str | None = None,
                 specular: str | None = None, terms_off: int = 0) -> np.ndarray:
    """Linear RGB (H, W, 3) float32 of the scene, row 0 at the top (``terms_off``: the
    equation's terms left out, :meth:`Renderer.render`)."""
    renderer = shared_renderer()
    target = shared_target(size)
    renderer.render(scene, target, shading, specular, terms_off)
    return target.read()
