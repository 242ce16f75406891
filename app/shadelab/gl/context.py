"""Create OpenGL contexts: a standalone one for headless work, or attach to a window's.

This is the only module that creates a context; the CLI, the viewer and the tests share it.

Headless contexts come from EGL first on Linux (no display needed), then from the platform's
native standalone context, moderngl's default backend: GLX on X11, WGL on Windows, CGL on
macOS (a 4.1 core context there: no shader may need more). ``SHADELAB_GL=egl|native`` forces
one; ``SHADELAB_LIBEGL`` (another libEGL) implies EGL. :func:`context_info` says which was
made and the driver behind it (``shadelab render -v``, the bench's machine block).
"""

from __future__ import annotations

import os
import sys

import moderngl

from shadelab.errors import ShadeLabError

GL_VERSION = 330  # GLSL 3.30 core: what every shader here is written for

_HEADLESS: moderngl.Context | None = None

NO_CONTEXT_HINT = ("cannot create a headless OpenGL context ({reasons}); on Linux install "
                   "Mesa's EGL and drivers, e.g. 'apt-get install libegl1 libgl1-mesa-dri', "
                   "or run under an X server (DISPLAY)")
BACKENDS = ("egl", "native")
NATIVE_NAMES = {"linux": "GLX", "win32": "WGL", "darwin": "CGL"}
_SET_PLATFORM = False  # True when PYOPENGL_PLATFORM was set here, not by the user


def _reason(exc: Exception) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def backend_order() -> list[str]:
    """The headless backends to try, in order (``SHADELAB_GL`` forces one)."""
    forced = os.environ.get("SHADELAB_GL", "").strip().lower()
    if forced in ("", "auto"):
        if os.environ.get("SHADELAB_LIBEGL"):
            return ["egl"]
        return ["egl", "native"] if sys.platform.startswith("linux") else ["native"]
    if forced not in BACKENDS:
        raise ShadeLabError(f"SHADELAB_GL='{forced}': expected egl, native or auto")
    return [forced]


def native_name() -> str:
    """GLX, WGL or CGL: what moderngl's default standalone backend is on this platform."""
    return NATIVE_NAMES.get("linux" if sys.platform.startswith("linux") else sys.platform,
                            "native")


def _pyopengl_platform(backend: str) -> None:
    """PyOpenGL (the stencil helpers) must load GL the way the context was made."""
    global _SET_PLATFORM
    if "OpenGL" in sys.modules:  # chosen for this process already
        return
    if "PYOPENGL_PLATFORM" not in os.environ or _SET_PLATFORM:
        if backend == "egl":
            os.environ["PYOPENGL_PLATFORM"] = "egl"  # PyOpenGL must not look for GLX
        elif sys.platform.startswith("linux"):
            os.environ["PYOPENGL_PLATFORM"] = "glx"
        else:
            os.environ.pop("PYOPENGL_PLATFORM", None)  # WGL / CGL: PyOpenGL's default
        _SET_PLATFORM = True


def _create(backend: str) -> moderngl.Context:
    _pyopengl_platform(backend)
    if backend == "egl":
        kwargs = {}
        if os.environ.get("SHADELAB_LIBEGL"):
            kwargs["libegl"] = os.environ["SHADELAB_LIBEGL"]
        return moderngl.create_context(standalone=True, backend="egl", require=GL_VERSION,
                                       **kwargs)
    return moderngl.create_context(standalone=True, require=GL_VERSION)


def create_headless_context() -> moderngl.Context:
    """A new standalone context: EGL, else the native one (see the module's notes).

    ``SHADELAB_LIBEGL`` names another libEGL (tests point it at a missing file to check the
    error message).
    """
    reasons = []
    for backend in backend_order():
        try:
            ctx = _create(backend)
        except Exception as exc:  # glcontext raises bare Exceptions with the loader's message
            label = "EGL" if backend == "egl" else f"native {native_name()}"
            reasons.append(f"{label}: {_reason(exc)}")
            continue
        if not isinstance(ctx.extra, dict):
            ctx.extra = {}
        ctx.extra["shadelab_backend"] = backend
        return ctx
    raise ShadeLabError(NO_CONTEXT_HINT.format(reasons="; ".join(reasons)))


def context_info(ctx: moderngl.Context) -> dict[str, str]:
    """``backend`` (egl, native GLX/WGL/CGL, or window), GL renderer, version and vendor."""
    extra = ctx.extra if isinstance(ctx.extra, dict) else {}
    backend = extra.get("shadelab_backend", "window")
    if backend == "native":
        backend = f"native ({native_name()})"
    info = ctx.info
    return {"backend": backend, "renderer": str(info.get("GL_RENDERER", "")),
            "version": str(info.get("GL_VERSION", "")), "vendor": str(info.get("GL_VENDOR", ""))}


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
