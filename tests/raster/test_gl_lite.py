"""gl/lite.py: the few raw-GL calls beside moderngl, checked like PyOpenGL's wrappers, without
importing OpenGL.GL (its every wrapper cost ~150 ms of the viewer's start)."""

from __future__ import annotations

import subprocess
import sys

import pytest

pytestmark = pytest.mark.gl


def test_lite_calls_return_what_pyopengl_returned_and_raise_on_a_gl_error(gl_ctx):
    from shadelab.gl import lite

    _ = gl_ctx.error
    name = lite.glGenRenderbuffers(1)
    assert isinstance(name, int) and name > 0
    lite.glDeleteRenderbuffers(1, [name])
    assert lite.glGetIntegerv(lite.GL_MAX_SAMPLES) >= 1
    from OpenGL.error import GLError

    with pytest.raises((lite.GLCallError, GLError)):  # PyOpenGL's errcheck, or ours
        lite.glEnable(0xFFFF)                         # GL_INVALID_ENUM
    assert gl_ctx.error == "GL_NO_ERROR"            # the check consumed it


def test_rendering_with_shadow_volumes_never_imports_opengl_gl():
    """Cornell and the lecture (stencil shadow volumes, MSAA) render without OpenGL.GL, and
    without PyOpenGL's raw per-version modules (lite declares its few entry points itself)."""
    code = ("import sys\n"
            "from shadelab.gl.context import headless_context\n"
            "from shadelab.gl.target import RenderTarget, max_msaa_samples\n"
            "from shadelab.raster.renderer import Renderer\n"
            "from shadelab.scene.preset import load_preset\n"
            "ctx = headless_context()\n"
            "renderer = Renderer(ctx)\n"
            "for name, samples in (('cornell', 1), ('lecture', 1), ('lecture', 4)):\n"
            "    target = RenderTarget(ctx, (64, 48), samples)\n"
            "    renderer.render(load_preset(name), target)\n"
            "    assert target.read().max() > 0\n"
            "    target.release()\n"
            "assert max_msaa_samples(ctx) >= 1\n"
            "print('OpenGL.GL' in sys.modules)\n"
            "print(sorted(m for m in sys.modules if m.startswith('OpenGL.raw.GL.VERSION.')))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["False", "[]"]
