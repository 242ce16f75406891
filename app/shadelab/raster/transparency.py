"""Transparent surfaces (kt > 0) drawn after the opaque ones, back to front, blended by the
lecture's two models, chosen per material (``Material.transparency``; the blend state is
:mod:`shadelab.gl.blend`):

* interpolated: I = (1 - kt) I1 + kt I2
* filtered:     I = I1 + kt Ot I2

I1 is the surface's own shaded color, I2 whatever lies behind it (the framebuffer so far).
Triangles of every transparent object are sorted together by their centroid's view depth, so
several overlapping transparent surfaces compose in the right order (intersecting triangles
are the limit of per-triangle sorting). They are depth-tested against the opaque surfaces but
write no depth. With shadow volumes on, transparent surfaces are lit without shadows (S_i = 1)
and still cast shadows unless ``cast_shadows = false``.
"""

from __future__ import annotations

import moderngl
import numpy as np

from shadelab.gl.blend import restore_blend, set_blend
from shadelab.raster.painter import draw_sorted, sort_back_to_front


def blend_reference(model: str, kt: float, Ot, I1: np.ndarray, I2: np.ndarray) -> np.ndarray:
    """The lecture's formulas in numpy (what the blend state must reproduce)."""
    if model == "filtered":
        return I1 + kt * np.asarray(Ot) * I2
    return (1.0 - kt) * I1 + kt * I2


def draw_transparent(renderer, scene, gpu_meshes, shading: str, view) -> None:
    """Pass 4: every transparent triangle, farthest first, blended over the frame."""
    ctx = renderer.ctx
    ctx.enable_only(moderngl.DEPTH_TEST | moderngl.BLEND)
    ctx.depth_func = "<"
    fbo = ctx.fbo
    fbo.depth_mask = False
    fbo.use()
    soup = sort_back_to_front(scene, [g.mesh for g in gpu_meshes])
    try:
        draw_sorted(renderer, scene, gpu_meshes, shading, soup,
                    lambda material: set_blend(ctx, material))
    finally:
        restore_blend(ctx)
        fbo.depth_mask = True
        fbo.use()
        ctx.enable_only(moderngl.DEPTH_TEST)
