"""The few raw-GL calls ShadeLab makes beside moderngl (render targets' depth-stencil
renderbuffers, stencil state, the constant blend color), from PyOpenGL's raw per-version
modules: ``from OpenGL import GL`` builds a wrapper for every entry point of every GL version
and extension (~150 ms of a viewer's start on two cores); these few import in about half.

Each call is checked as PyOpenGL's own wrappers are: a GL error raises (PyOpenGL's GLError
where its raw functions check errors, else :class:`GLCallError` naming the call). The
constants are the GL specification's numbers. Import this module only after the context
module chose PyOpenGL's platform (as ``OpenGL.GL``).
"""

from __future__ import annotations

import ctypes

import numpy as np
from OpenGL.raw.GL.VERSION import GL_1_0, GL_1_1, GL_1_4, GL_2_0, GL_3_0

GL_NO_ERROR = 0
GL_NEVER, GL_LESS, GL_EQUAL, GL_LEQUAL = 0x0200, 0x0201, 0x0202, 0x0203
GL_GREATER, GL_NOTEQUAL, GL_GEQUAL, GL_ALWAYS = 0x0204, 0x0205, 0x0206, 0x0207
GL_ZERO, GL_ONE = 0, 1
GL_FRONT, GL_BACK, GL_FRONT_AND_BACK = 0x0404, 0x0405, 0x0408
GL_KEEP, GL_REPLACE, GL_INCR, GL_DECR, GL_INVERT = 0x1E00, 0x1E01, 0x1E02, 0x1E03, 0x150A
GL_INCR_WRAP, GL_DECR_WRAP = 0x8507, 0x8508
GL_STENCIL_TEST, GL_DEPTH_TEST, GL_BLEND = 0x0B90, 0x0B71, 0x0BE2
GL_DEPTH_CLAMP, GL_POLYGON_OFFSET_FILL = 0x864F, 0x8037
GL_COLOR_BUFFER_BIT, GL_DEPTH_BUFFER_BIT, GL_STENCIL_BUFFER_BIT = 0x4000, 0x0100, 0x0400
GL_NEAREST, GL_LINEAR = 0x2600, 0x2601
GL_TEXTURE_2D = 0x0DE1
GL_STENCIL_INDEX, GL_UNSIGNED_BYTE = 0x1901, 0x1401
GL_RGBA32F, GL_DEPTH24_STENCIL8 = 0x8814, 0x88F0
GL_RENDERBUFFER, GL_FRAMEBUFFER = 0x8D41, 0x8D40
GL_READ_FRAMEBUFFER, GL_DRAW_FRAMEBUFFER = 0x8CA8, 0x8CA9
GL_COLOR_ATTACHMENT0, GL_DEPTH_STENCIL_ATTACHMENT = 0x8CE0, 0x821A
GL_FRAMEBUFFER_COMPLETE = 0x8CD5
GL_MAX_SAMPLES, GL_SAMPLES = 0x8D57, 0x80A9


class GLCallError(RuntimeError):
    """A GL error right after one of these calls (``glX(...): GL error 0x0502``)."""


def _checked(function):
    name = function.__name__

    def call(*args):
        result = function(*args)
        error = GL_1_0.glGetError()
        if error != GL_NO_ERROR:
            raise GLCallError(f"{name}{args}: GL error 0x{int(error):04x}")
        return result

    call.__name__ = name
    return call


glFlush = _checked(GL_1_0.glFlush)
glEnable = _checked(GL_1_0.glEnable)
glDisable = _checked(GL_1_0.glDisable)
glClear = _checked(GL_1_0.glClear)
glClearStencil = _checked(GL_1_0.glClearStencil)
glStencilFunc = _checked(GL_1_0.glStencilFunc)
glStencilMask = _checked(GL_1_0.glStencilMask)
glStencilOp = _checked(GL_1_0.glStencilOp)
glStencilOpSeparate = _checked(GL_2_0.glStencilOpSeparate)
glPolygonOffset = _checked(GL_1_1.glPolygonOffset)
glBlendFunc = _checked(GL_1_0.glBlendFunc)
glBlendColor = _checked(GL_1_4.glBlendColor)
glBindRenderbuffer = _checked(GL_3_0.glBindRenderbuffer)
glRenderbufferStorage = _checked(GL_3_0.glRenderbufferStorage)
glRenderbufferStorageMultisample = _checked(GL_3_0.glRenderbufferStorageMultisample)
glBindFramebuffer = _checked(GL_3_0.glBindFramebuffer)
glFramebufferTexture2D = _checked(GL_3_0.glFramebufferTexture2D)
glFramebufferRenderbuffer = _checked(GL_3_0.glFramebufferRenderbuffer)
glBlitFramebuffer = _checked(GL_3_0.glBlitFramebuffer)
_check_status = _checked(GL_3_0.glCheckFramebufferStatus)


def glCheckFramebufferStatus(target: int) -> int:
    return int(_check_status(target))


def _gen(function, n: int):
    names = np.zeros(n, dtype=np.uint32)
    _checked(function)(n, names)
    return int(names[0]) if n == 1 else [int(v) for v in names]


def glGenRenderbuffers(n: int):
    """``n`` new renderbuffer names (an int for one, as PyOpenGL returns)."""
    return _gen(GL_3_0.glGenRenderbuffers, n)


def glGenFramebuffers(n: int):
    return _gen(GL_3_0.glGenFramebuffers, n)


def glDeleteRenderbuffers(n: int, names) -> None:
    _checked(GL_3_0.glDeleteRenderbuffers)(n, np.asarray(names, dtype=np.uint32))


def glDeleteFramebuffers(n: int, names) -> None:
    _checked(GL_3_0.glDeleteFramebuffers)(n, np.asarray(names, dtype=np.uint32))


def glGetIntegerv(pname: int) -> int:
    value = np.zeros(16, dtype=np.int32)   # room for any vector query
    _checked(GL_1_0.glGetIntegerv)(pname, value)
    return int(value[0])


def glGetInternalformativ(target: int, internal_format: int, pname: int, count: int):
    """The query's ``count`` integers (GL 4.2; GLCallError where the GL lacks it)."""
    from OpenGL.raw.GL.VERSION import GL_4_2

    values = np.zeros(max(count, 1), dtype=np.int32)
    _checked(GL_4_2.glGetInternalformativ)(target, internal_format, pname, count, values)
    return values


def glReadPixels(x: int, y: int, width: int, height: int, format: int, kind: int) -> bytes:
    """Stencil indices or other one-byte-per-pixel reads (``GL_UNSIGNED_BYTE``) as bytes."""
    if kind != GL_UNSIGNED_BYTE or format != GL_STENCIL_INDEX:
        raise ValueError("glReadPixels here reads GL_STENCIL_INDEX as GL_UNSIGNED_BYTE only")
    out = (ctypes.c_ubyte * (width * height))()
    GL_1_0.glPixelStorei(0x0D05, 1)   # GL_PACK_ALIGNMENT: rows of any width packed tight
    _checked(GL_1_0.glReadPixels)(x, y, width, height, format, kind, out)
    return bytes(out)
