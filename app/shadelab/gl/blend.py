"""Blend state for the lecture's two transparency models, set through raw GL where moderngl
has no call for it (the constant blend color).

* interpolated: I = (1 - kt) I1 + kt I2   (src * (1 - kt) + dst * kt)
* filtered:     I = I1 + kt Ot I2         (src * 1 + dst * (kt Ot))
"""

from __future__ import annotations

import moderngl

GL_CONSTANT_COLOR = 0x8001
GL_CONSTANT_ALPHA = 0x8003
GL_ONE_MINUS_CONSTANT_ALPHA = 0x8004


def set_blend(ctx: moderngl.Context, material) -> None:
    """Blend state for one material: off when opaque, else the material's model."""
    from shadelab.gl import lite as GL  # late: the context module picks PyOpenGL's platform

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
    """Back to moderngl's default blending (and a zero constant color)."""
    from shadelab.gl import lite as GL

    _ = ctx.error
    GL.glBlendColor(0.0, 0.0, 0.0, 0.0)
    ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
