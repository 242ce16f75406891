"""Create OpenGL contexts: EGL standalone for headless work, or attach to a window's context.

This is the only module that creates a context; the CLI, the viewer and the tests share it.
"""

from __future__ import annotations

import os

import moderngl

from shadelab.errors import ShadeLabError

GL_VERSION = 330  # GLSL 3.30 core: what every shader here is written for

_HEADLESS: moderngl.Context | None = None

NO_EGL_HINT = ("cannot create a headless OpenGL context through EGL ({reason}); install Mesa's "
               "EGL and drivers, e.g. 'apt-get install libegl1 libgl1-mesa-dri'")


def create_headless_context() -> moderngl.Context:
    """A new standalone EGL context (no X display needed).

    ``SHADELAB_LIBEGL`` names another libEGL (tests point it at a missing file to check the
    error message).
    """
    os.environ.setdefault("PYOPENGL_PLATFORM", "egl")  # PyOpenGL must not look for GLX
    kwargs = {}
    if os.environ.get("SHADELAB_LIBEGL"):
        kwargs["libegl"] = os.environ["SHADELAB_LIBEGL"]
    try:
        return moderngl.create_context(standalone=True, backend="egl", require=GL_VERSION,
                                       **kwargs)
    except Exception as exc:  # glcontext raises bare Exceptions with the loader's message
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ShadeLabError(NO_EGL_HINT.format(reason=reason)) from None


def headless_context() -> moderngl.Context:
    """The process's shared headless context, created on first use."""
    global _HEADLESS
    if _HEADLESS is None:
        _HEADLESS = create_headless_context()
    return _HEADLESS


def make_current(ctx: moderngl.Context) -> None:
    """Make ``ctx`` the thread's current context again.

    Creating a standalone context makes it current; after a second one is made (and released),
    the first must be made current before it is used again.
    """
    ctx.__enter__()  # glcontext: make current (the matching __exit__ is never needed here)


def attach_to_current() -> moderngl.Context:
    """Wrap the context a window toolkit (GLFW, imgui-bundle) made current."""
    return moderngl.create_context(require=GL_VERSION)
