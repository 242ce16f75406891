"""Transparent surfaces (kt > 0) drawn after the opaque ones, back to front, blended by the
lecture's two models, chosen per material (``Material.transparency``):

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

from shadelab.render.painter import draw_sorted, sort_back_to_front
from shadelab.scene.model import Material

GL_CONSTANT_COLOR = 0x8001
GL_CONSTANT_ALPHA = 0x8003
GL_ONE_MINUS_CONSTANT_ALPHA = 0x8004


def blend_reference(model: str, kt: float, Ot, I1: np.ndarray, I2: np.ndarray) -> np.ndarray:
    """The lecture's formulas in numpy (what the blend state must reproduce)."""
    if model == "filtered":
        return I1 + kt * np.asarray(Ot) * I2
    return (1.0 - kt) * I1 + kt * I2


def set_blend(ctx: moderngl.Context, material: Material) -> None:
    """Blend state for one material: off when opaque, else the material's model."""
    from OpenGL import GL

    if material.kt <= 0.0:
        ctx.disable(moderngl.BLEND)
        return
    ctx.enable(moderngl.BLEND)
    _ = ctx.error
    kt = float(material.kt)
    if material.transparency == "filtered":  # src * 1 + dst * (kt Ot)
        GL.glBlendColor(*(kt * c for c in material.Ot), 1.0)
        GL.glBlendFunc(GL.GL_ONE, GL_CONSTANT_COLOR)
    else:  # src * (1 - kt) + dst * kt
        GL.glBlendColor(0.0, 0.0, 0.0, kt)
        GL.glBlendFunc(GL_ONE_MINUS_CONSTANT_ALPHA, GL_CONSTANT_ALPHA)


def restore_blend(ctx: moderngl.Context) -> None:
    from OpenGL import GL

    _ = ctx.error
    GL.glBlendColor(0.0, 0.0, 0.0, 0.0)
    ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA


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
