"""The few raw-GL calls ShadeLab makes beside moderngl (render targets' depth-stencil
renderbuffers, stencil state, the constant blend color), made as PyOpenGL's raw modules make
them: ``from OpenGL import GL`` builds a wrapper for every entry point of every GL version
and extension (~150 ms of a viewer's start on two cores), and even the raw per-version modules
(``OpenGL.raw.GL.VERSION.GL_1_0`` ...) build ~600 entry points and ~2000 constants for the two
dozen used here (~25 ms more); each entry point below is declared as its raw module declares
it (the same ``createFunction`` on the same platform library, argument types and error
checker), the rest never built.

Each call is checked as PyOpenGL's own wrappers are: a GL error raises (PyOpenGL's GLError
where its raw functions check errors, else :class:`GLCallError` naming the call). The
constants are the GL specification's numbers. Import this module only after the context
module chose PyOpenGL's platform (as ``OpenGL.GL``).
"""

from __future__ import annotations

import ctypes

import numpy as np
from OpenGL import arrays
from OpenGL import platform as _p
from OpenGL.raw.GL import _errors
from OpenGL.raw.GL import _types as _cs


def _in(version: str):
    """Declare an entry point of GL ``version`` as ``OpenGL.raw.GL.VERSION.GL_<version>``
    does (its ``_f``)."""
    def declare(function):
        return _p.createFunction(function, _p.PLATFORM.GL, f"GL_VERSION_GL_{version}",
                                 error_checker=_errors._error_checker)
    return declare


# ---------------------------------------------------------------- entry points (PyOpenGL raw)
# the argument lists of PyOpenGL 3.1's generated OpenGL/raw/GL/VERSION/GL_*.py


class raw:
    """PyOpenGL's raw entry points (its own error checker only; the checked calls of this
    module are below): ``raw.glClear`` is ``OpenGL.raw.GL.VERSION.GL_1_0.glClear``."""

    @_in("1_0")
    @_p.types(None,)
    def glFlush(): pass

    @_in("1_0")
    @_p.types(None, _cs.GLenum)
    def glEnable(cap): pass

    @_in("1_0")
    @_p.types(None, _cs.GLenum)
    def glDisable(cap): pass

    @_in("1_0")
    @_p.types(None, _cs.GLbitfield)
    def glClear(mask): pass

    @_in("1_0")
    @_p.types(None, _cs.GLint)
    def glClearStencil(s): pass

    @_in("1_0")
    @_p.types(None, _cs.GLenum, _cs.GLint, _cs.GLuint)
    def glStencilFunc(func, ref, mask): pass

    @_in("1_0")
    @_p.types(None, _cs.GLuint)
    def glStencilMask(mask): pass

    @_in("1_0")
    @_p.types(None, _cs.GLenum, _cs.GLenum, _cs.GLenum)
    def glStencilOp(fail, zfail, zpass): pass

    @_in("1_0")
    @_p.types(None, _cs.GLenum, _cs.GLenum)
    def glBlendFunc(sfactor, dfactor): pass

    @_in("1_0")
    @_p.types(_cs.GLenum,)
    def glGetError(): pass

    @_in("1_0")
    @_p.types(None, _cs.GLenum, arrays.GLintArray)
    def glGetIntegerv(pname, data): pass

    @_in("1_0")
    @_p.types(None, _cs.GLenum, _cs.GLint)
    def glPixelStorei(pname, param): pass

    @_in("1_0")
    @_p.types(None, _cs.GLint, _cs.GLint, _cs.GLsizei, _cs.GLsizei, _cs.GLenum, _cs.GLenum,
              ctypes.c_void_p)
    def glReadPixels(x, y, width, height, format, type, pixels): pass

    @_in("1_1")
    @_p.types(None, _cs.GLfloat, _cs.GLfloat)
    def glPolygonOffset(factor, units): pass

    @_in("1_4")
    @_p.types(None, _cs.GLfloat, _cs.GLfloat, _cs.GLfloat, _cs.GLfloat)
    def glBlendColor(red, green, blue, alpha): pass

    @_in("2_0")
    @_p.types(None, _cs.GLenum, _cs.GLenum, _cs.GLenum, _cs.GLenum)
    def glStencilOpSeparate(face, sfail, dpfail, dppass): pass

    @_in("3_0")
    @_p.types(None, _cs.GLenum, _cs.GLuint)
    def glBindRenderbuffer(target, renderbuffer): pass

    @_in("3_0")
    @_p.types(None, _cs.GLenum, _cs.GLenum, _cs.GLsizei, _cs.GLsizei)
    def glRenderbufferStorage(target, internalformat, width, height): pass

    @_in("3_0")
    @_p.types(None, _cs.GLenum, _cs.GLsizei, _cs.GLenum, _cs.GLsizei, _cs.GLsizei)
    def glRenderbufferStorageMultisample(target, samples, internalformat, width,
                                         height): pass

    @_in("3_0")
    @_p.types(None, _cs.GLenum, _cs.GLuint)
    def glBindFramebuffer(target, framebuffer): pass

    @_in("3_0")
    @_p.types(None, _cs.GLenum, _cs.GLenum, _cs.GLenum, _cs.GLuint, _cs.GLint)
    def glFramebufferTexture2D(target, attachment, textarget, texture, level): pass

    @_in("3_0")
    @_p.types(None, _cs.GLenum, _cs.GLenum, _cs.GLenum, _cs.GLuint)
    def glFramebufferRenderbuffer(target, attachment, renderbuffertarget,
                                  renderbuffer): pass

    @_in("3_0")
    @_p.types(None, _cs.GLint, _cs.GLint, _cs.GLint, _cs.GLint, _cs.GLint, _cs.GLint,
              _cs.GLint, _cs.GLint, _cs.GLbitfield, _cs.GLenum)
    def glBlitFramebuffer(srcX0, srcY0, srcX1, srcY1, dstX0, dstY0, dstX1, dstY1,
                          mask, filter): pass

    @_in("3_0")
    @_p.types(_cs.GLenum, _cs.GLenum)
    def glCheckFramebufferStatus(target): pass

    @_in("3_0")
    @_p.types(None, _cs.GLsizei, arrays.GLuintArray)
    def glGenRenderbuffers(n, renderbuffers): pass

    @_in("3_0")
    @_p.types(None, _cs.GLsizei, arrays.GLuintArray)
    def glGenFramebuffers(n, framebuffers): pass

    @_in("3_0")
    @_p.types(None, _cs.GLsizei, arrays.GLuintArray)
    def glDeleteRenderbuffers(n, renderbuffers): pass

    @_in("3_0")
    @_p.types(None, _cs.GLsizei, arrays.GLuintArray)
    def glDeleteFramebuffers(n, framebuffers): pass

    @_in("4_2")
    @_p.types(None, _cs.GLenum, _cs.GLenum, _cs.GLenum, _cs.GLsizei, arrays.GLintArray)
    def glGetInternalformativ(target, internalformat, pname, count, params): pass


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
        error = raw.glGetError()
        if error != GL_NO_ERROR:
            raise GLCallError(f"{name}{args}: GL error 0x{int(error):04x}")
        return result

    call.__name__ = name
    return call


glFlush = _checked(raw.glFlush)
glEnable = _checked(raw.glEnable)
glDisable = _checked(raw.glDisable)
glClear = _checked(raw.glClear)
glClearStencil = _checked(raw.glClearStencil)
glStencilFunc = _checked(raw.glStencilFunc)
glStencilMask = _checked(raw.glStencilMask)
glStencilOp = _checked(raw.glStencilOp)
glStencilOpSeparate = _checked(raw.glStencilOpSeparate)
glPolygonOffset = _checked(raw.glPolygonOffset)
glBlendFunc = _checked(raw.glBlendFunc)
glBlendColor = _checked(raw.glBlendColor)
glBindRenderbuffer = _checked(raw.glBindRenderbuffer)
glRenderbufferStorage = _checked(raw.glRenderbufferStorage)
glRenderbufferStorageMultisample = _checked(raw.glRenderbufferStorageMultisample)
glBindFramebuffer = _checked(raw.glBindFramebuffer)
glFramebufferTexture2D = _checked(raw.glFramebufferTexture2D)
glFramebufferRenderbuffer = _checked(raw.glFramebufferRenderbuffer)
glBlitFramebuffer = _checked(raw.glBlitFramebuffer)
_check_status = _checked(raw.glCheckFramebufferStatus)


def glCheckFramebufferStatus(target: int) -> int:
    return int(_check_status(target))


# Arrays are passed as ctypes arrays: a numpy one loads PyOpenGL's numpy handler, which imports
# the raw GL_1_1 and GL_1_0 modules (~15 ms of the viewer's start) for its type constants.


def _uints(values) -> ctypes.Array:
    values = np.asarray(values, dtype=np.uint32).ravel()
    return (ctypes.c_uint * len(values))(*(int(v) for v in values))


def _gen(function, n: int):
    names = (ctypes.c_uint * n)()
    _checked(function)(n, names)
    return int(names[0]) if n == 1 else [int(v) for v in names]


def glGenRenderbuffers(n: int):
    """``n`` new renderbuffer names (an int for one, as PyOpenGL returns)."""
    return _gen(raw.glGenRenderbuffers, n)


def glGenFramebuffers(n: int):
    return _gen(raw.glGenFramebuffers, n)


def glDeleteRenderbuffers(n: int, names) -> None:
    _checked(raw.glDeleteRenderbuffers)(n, _uints(names))


def glDeleteFramebuffers(n: int, names) -> None:
    _checked(raw.glDeleteFramebuffers)(n, _uints(names))


def glGetIntegerv(pname: int) -> int:
    value = (ctypes.c_int * 16)()   # room for any vector query
    _checked(raw.glGetIntegerv)(pname, value)
    return int(value[0])


def glGetInternalformativ(target: int, internal_format: int, pname: int, count: int):
    """The query's ``count`` integers (GL 4.2; GLCallError where the GL lacks it)."""
    values = (ctypes.c_int * max(count, 1))()
    _checked(raw.glGetInternalformativ)(target, internal_format, pname, count, values)
    return np.array(values, dtype=np.int32)


def glReadPixels(x: int, y: int, width: int, height: int, format: int, kind: int) -> bytes:
    """Stencil indices or other one-byte-per-pixel reads (``GL_UNSIGNED_BYTE``) as bytes."""
    if kind != GL_UNSIGNED_BYTE or format != GL_STENCIL_INDEX:
        raise ValueError("glReadPixels here reads GL_STENCIL_INDEX as GL_UNSIGNED_BYTE only")
    out = (ctypes.c_ubyte * (width * height))()
    raw.glPixelStorei(0x0D05, 1)   # GL_PACK_ALIGNMENT: rows of any width packed tight
    _checked(raw.glReadPixels)(x, y, width, height, format, kind, out)
    return bytes(out)
