"""An offscreen render target: float RGBA color plus a 24-bit depth / 8-bit stencil buffer,
optionally multisampled (resolved into the color texture with a blit).

moderngl has no stencil API (moderngl#676), so the depth-stencil renderbuffer is made with
PyOpenGL on moderngl's current context and the framebuffer wrapped by ``detect_framebuffer``.
"""

from __future__ import annotations

import moderngl
import numpy as np


def _gl():
    from shadelab.gl import lite  # imported late: the context module picks PyOpenGL's platform

    return lite


def _raw_gl():
    return _gl().raw  # PyOpenGL's raw entry points, unchecked here (see RenderTarget.clear)


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


def max_msaa_samples(ctx: moderngl.Context) -> int:
    """The most samples an RGBA32F + DEPTH24_STENCIL8 multisample target may have here (1:
    no multisampling; then the viewer falls back to 2x2 supersampling)."""
    GL = _gl()
    _ = ctx.error
    try:
        counts = [int(GL.glGetIntegerv(GL.GL_MAX_SAMPLES))]
        for fmt in (GL.GL_RGBA32F, GL.GL_DEPTH24_STENCIL8):
            counts.append(int(GL.glGetInternalformativ(GL.GL_RENDERBUFFER, fmt, GL.GL_SAMPLES,
                                                       1)[0]))
    except Exception:  # no GL 4.2 internal-format query: GL_MAX_SAMPLES alone
        _ = ctx.error
        return max(int(getattr(ctx, "max_samples", 1) or 1), 1)
    return max(min(counts), 1)


class RenderTarget:
    """Color texture (RGBA32F, linear radiance) + DEPTH24_STENCIL8 renderbuffer.

    With ``samples`` > 1 the passes draw into a multisample framebuffer (RGBA32F and
    DEPTH24_STENCIL8 multisample renderbuffers: stencil shadow volumes keep working per
    sample) and :meth:`resolve` blits it into ``color``; ``samples`` is clamped to what the GL
    allows (:func:`max_msaa_samples`), so ``target.samples`` says what was made.
    """

    def __init__(self, ctx: moderngl.Context, size: tuple[int, int], samples: int = 1):
        GL = _gl()
        _ = ctx.error  # reading the error clears it, so PyOpenGL's checks see only ours
        self.ctx = ctx
        self.size = size
        self.samples = 1
        if samples > 1:
            self.samples = min(int(samples), max_msaa_samples(ctx))
        self.color = ctx.texture(size, 4, dtype="f4")
        self._renderbuffers: list[int] = []
        self._framebuffers: list[int] = []
        self._resolve_fbo = None
        if self.samples > 1:
            resolve = self._framebuffer_with(GL, self.color.glo, None)
            self._resolve_fbo = ctx.detect_framebuffer(resolve)
            color_rb = self._make_renderbuffer(GL, GL.GL_RGBA32F)
            depth_rb = self._make_renderbuffer(GL, GL.GL_DEPTH24_STENCIL8)
            self._framebuffer = self._framebuffer_with(GL, None, depth_rb, color_rb)
        else:
            depth_rb = self._make_renderbuffer(GL, GL.GL_DEPTH24_STENCIL8)
            self._framebuffer = self._framebuffer_with(GL, self.color.glo, depth_rb)
        self._renderbuffer = depth_rb
        self.fbo = ctx.detect_framebuffer(self._framebuffer)

    def _make_renderbuffer(self, GL, fmt) -> int:
        name = int(GL.glGenRenderbuffers(1))
        self._renderbuffers.append(name)
        GL.glBindRenderbuffer(GL.GL_RENDERBUFFER, name)
        if self.samples > 1:
            GL.glRenderbufferStorageMultisample(GL.GL_RENDERBUFFER, self.samples, fmt,
                                                *self.size)
        else:
            GL.glRenderbufferStorage(GL.GL_RENDERBUFFER, fmt, *self.size)
        return name

    def _framebuffer_with(self, GL, texture, depth_rb, color_rb=None) -> int:
        name = int(GL.glGenFramebuffers(1))
        self._framebuffers.append(name)
        GL.glBindFramebuffer(GL.GL_FRAMEBUFFER, name)
        if texture is not None:
            GL.glFramebufferTexture2D(GL.GL_FRAMEBUFFER, GL.GL_COLOR_ATTACHMENT0,
                                      GL.GL_TEXTURE_2D, texture, 0)
        if color_rb is not None:
            GL.glFramebufferRenderbuffer(GL.GL_FRAMEBUFFER, GL.GL_COLOR_ATTACHMENT0,
                                         GL.GL_RENDERBUFFER, color_rb)
        if depth_rb is not None:
            GL.glFramebufferRenderbuffer(GL.GL_FRAMEBUFFER, GL.GL_DEPTH_STENCIL_ATTACHMENT,
                                         GL.GL_RENDERBUFFER, depth_rb)
        status = GL.glCheckFramebufferStatus(GL.GL_FRAMEBUFFER)
        if status != GL.GL_FRAMEBUFFER_COMPLETE:
            raise RuntimeError(f"render target incomplete (status 0x{status:x})")
        return name

    def resolve(self) -> None:
        """Average the samples into ``color`` (a no-op without multisampling)."""
        if self._resolve_fbo is None:
            return
        GL = _gl()
        _ = self.ctx.error
        w, h = self.size
        GL.glBindFramebuffer(GL.GL_READ_FRAMEBUFFER, self._framebuffers[-1])
        GL.glBindFramebuffer(GL.GL_DRAW_FRAMEBUFFER, self._framebuffers[0])
        GL.glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL.GL_COLOR_BUFFER_BIT, GL.GL_NEAREST)
        self.fbo.use()  # moderngl's record of the bound framebuffer stays true

    def read_pixel(self, x: int, y: int) -> np.ndarray:
        """Linear RGB at (x, y), row 0 at the top, after resolving (float32, 3)."""
        self.resolve()
        fbo = self._resolve_fbo or self.fbo
        raw = fbo.read(viewport=(x, self.size[1] - 1 - y, 1, 1), components=3, dtype="f4")
        return np.frombuffer(raw, dtype=np.float32).copy()

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
        # PyOpenGL's raw entry points: no glGetError after each call (three per frame, the
        # checked ones cost ~0.1 ms); none of these can fail on a complete framebuffer
        raw = _raw_gl()
        raw.glStencilMask(0xFF)
        raw.glClearStencil(stencil)
        raw.glClear(GL.GL_STENCIL_BUFFER_BIT)

    def read(self) -> np.ndarray:
        """Linear RGB (H, W, 3) float32, row 0 at the top."""
        self.resolve()
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
        release_framebuffer(self.ctx, self.fbo, self.color,
                            *([self._resolve_fbo] if self._resolve_fbo is not None else []))
        GL.glDeleteFramebuffers(len(self._framebuffers), self._framebuffers)
        GL.glDeleteRenderbuffers(len(self._renderbuffers), self._renderbuffers)
