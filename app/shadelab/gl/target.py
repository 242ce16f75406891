"""An offscreen render target: float RGBA color plus a 24-bit depth / 8-bit stencil buffer.

moderngl has no stencil API (moderngl#676), so the depth-stencil renderbuffer is made with
PyOpenGL on moderngl's current context and the framebuffer wrapped by ``detect_framebuffer``.
"""

from __future__ import annotations

import moderngl
import numpy as np


def _gl():
    from OpenGL import GL  # imported late: the context module picks PyOpenGL's platform

    return GL


def bind_anchor(ctx: moderngl.Context) -> None:
    """Bind the context's own 1x1 framebuffer, which is never released.

    moderngl re-binds "the framebuffer bound before" after creating a framebuffer; if that one
    was released, GL reports GL_INVALID_OPERATION (and PyOpenGL raises it later, somewhere
    else). Binding the anchor before releasing any framebuffer keeps that record valid.
    """
    if not isinstance(ctx.extra, dict):
        ctx.extra = {}
    anchor = ctx.extra.get("shadelab_anchor_fbo")
    if anchor is None:
        anchor = ctx.extra["shadelab_anchor_fbo"] = ctx.simple_framebuffer((1, 1))
        _ = ctx.error  # creating it may report the stale binding it replaces
    anchor.use()


def release_framebuffer(ctx: moderngl.Context, *objects) -> None:
    """Release framebuffers (and their attachments) without leaving a dangling binding."""
    bind_anchor(ctx)
    for obj in objects:
        obj.release()


class RenderTarget:
    """Color texture (RGBA32F, linear radiance) + DEPTH24_STENCIL8 renderbuffer."""

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int]):
        GL = _gl()
        _ = ctx.error  # reading the error clears it, so PyOpenGL's checks see only ours
        self.ctx = ctx
        self.size = size
        self.color = ctx.texture(size, 4, dtype="f4")
        self._renderbuffer = int(GL.glGenRenderbuffers(1))
        GL.glBindRenderbuffer(GL.GL_RENDERBUFFER, self._renderbuffer)
        GL.glRenderbufferStorage(GL.GL_RENDERBUFFER, GL.GL_DEPTH24_STENCIL8, *size)
        self._framebuffer = int(GL.glGenFramebuffers(1))
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, self._framebuffer)
        GL.glFramebufferTexture2D(GL.GL_FRAMEBUFFER, GL.GL_COLOR_ATTACHMENT0, GL.GL_TEXTURE_2D,
                                  self.color.glo, 0)
        GL.glFramebufferRenderbuffer(GL.GL_FRAMEBUFFER, GL.GL_DEPTH_STENCIL_ATTACHMENT,
                                     GL.GL_RENDERBUFFER, self._renderbuffer)
        status = GL.glCheckFramebufferStatus(GL.GL_FRAMEBUFFER)
        if status != GL.GL_FRAMEBUFFER_COMPLETE:
            raise RuntimeError(f"render target incomplete (status 0x{status:x})")
        self.fbo = ctx.detect_framebuffer(self._framebuffer)

    def use(self) -> None:
        self.fbo.use()

    def clear(self, color=(0.0, 0.0, 0.0), stencil: int = 0) -> None:
        """Clear color, depth and stencil (``fbo.clear`` alone never clears stencil)."""
        GL = _gl()
        _ = self.ctx.error  # a stale moderngl error would be blamed on PyOpenGL's next call
        self.fbo.use()
        self.fbo.depth_mask = True
        self.fbo.color_mask = (True, True, True, True)
        self.fbo.clear(*color, 1.0, depth=1.0)
        GL.glStencilMask(0xFF)
        GL.glClearStencil(stencil)
        GL.glClear(GL.GL_STENCIL_BUFFER_BIT)

    def read(self) -> np.ndarray:
        """Linear RGB (H, W, 3) float32, row 0 at the top."""
        self.ctx.finish()
        w, h = self.size
        data = np.frombuffer(self.color.read(), dtype=np.float32).reshape(h, w, 4)
        return np.ascontiguousarray(data[::-1, :, :3])

    def read_stencil(self) -> np.ndarray:
        """Stencil values (H, W) uint8, row 0 at the top."""
        GL = _gl()
        self.fbo.use()
        w, h = self.size
        raw = GL.glReadPixels(0, 0, w, h, GL.GL_STENCIL_INDEX, GL.GL_UNSIGNED_BYTE)
        return np.frombuffer(raw, dtype=np.uint8).reshape(h, w)[::-1].copy()

    def release(self) -> None:
        GL = _gl()
        release_framebuffer(self.ctx, self.fbo, self.color)
        GL.glDeleteFramebuffers(1, [self._framebuffer])
        GL.glDeleteRenderbuffers(1, [self._renderbuffer])
