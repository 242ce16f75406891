"""Headless contexts on every desktop OS: EGL, the native standalone context (GLX under a
private Xvfb here) matching EGL within the golden tolerance, SHADELAB_GL, and shaders that stay
within GL 4.1 core (macOS's ceiling)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from gui_harness import private_xvfb
from shadelab.resources import shaders_dir
from shadelab.testing import assert_images_close

SIZE = "96x72"
MAX_GLSL = 410


def _env(**extra) -> dict:
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYOPENGL_PLATFORM", "SHADELAB_GL", "SHADELAB_LIBEGL", "DISPLAY",
                        "WAYLAND_DISPLAY")}
    env.update(extra)
    return env


def _shadelab(args: list[str], env: dict, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "shadelab", *args], env=env, cwd=cwd,
                          capture_output=True, text=True, timeout=300)


@pytest.fixture(scope="module")
def xvfb():
    """A private Xvfb server (as tests/gui/test_gui.py starts one); yields its DISPLAY."""
    yield from private_xvfb("320x240x24", why="the GLX path needs a display")

@pytest.mark.gl
@pytest.mark.slow
@pytest.mark.parametrize("preset, shading", [("lecture", "phong"), ("cornell", "gouraud"),
                                             ("shadows", "phong")])
def test_native_glx_matches_egl(gl_ctx, xvfb, tmp_path, preset, shading):
    import shadelab

    out = _shadelab(["render", preset, "-o", "native.png", "--npy", "native.npy", "--size", SIZE,
                     "--shading", shading, "-v"], _env(SHADELAB_GL="native", DISPLAY=xvfb),
                    tmp_path)
    assert out.returncode == 0, out.stderr
    assert "gl: native (GLX)," in out.stdout
    native = np.load(tmp_path / "native.npy")
    egl = shadelab.render(preset, size=SIZE, shading=shading)
    assert_images_close(shadelab.Image(native, egl.exposure), egl, "golden",
                        name=f"native-{preset}", output_dir=tmp_path)


@pytest.mark.gl
def test_verbose_render_names_the_egl_context(gl_ctx, tmp_path):
    out = _shadelab(["render", "cornell", "-o", "x.png", "--size", "8x8", "-v"],
                    _env(SHADELAB_GL="egl"), tmp_path)
    assert out.returncode == 0, out.stderr
    line = next(s for s in out.stdout.splitlines() if s.startswith("gl: "))
    assert re.match(r"gl: egl, .+, OpenGL \d\.\d", line), line


@pytest.mark.parametrize("env, message", [
    ({"SHADELAB_GL": "vulkan"}, "SHADELAB_GL='vulkan': expected egl, native or auto"),
    ({"SHADELAB_GL": "egl", "SHADELAB_LIBEGL": "/nonexistent/libEGL.so"}, "EGL: "),
])
def test_forced_backend_failures_are_one_line(tmp_path, env, message):
    out = _shadelab(["render", "cornell", "-o", "x.png", "--size", "8x8"], _env(**env), tmp_path)
    assert out.returncode == 2, out.stderr
    assert out.stderr.startswith("shadelab: error: ") and out.stderr.count("\n") == 1
    assert message in out.stderr and "Traceback" not in out.stderr
    assert not (tmp_path / "x.png").exists()


def test_when_every_backend_fails_each_reason_is_named(monkeypatch):
    """(glcontext's GLX falls back to display :0, so a real failure depends on the machine.)"""
    from shadelab.errors import ShadeLabError
    from shadelab.gl import context

    def refuse(**kwargs):
        raise Exception("egl: no device" if kwargs.get("backend") == "egl"
                        else "(standalone) XOpenDisplay: cannot open display\nmore")

    monkeypatch.setattr(context.moderngl, "create_context", refuse)
    monkeypatch.setattr(context, "_pyopengl_platform", lambda backend: None)
    monkeypatch.delenv("SHADELAB_GL", raising=False)
    monkeypatch.delenv("SHADELAB_LIBEGL", raising=False)
    monkeypatch.setattr(context.sys, "platform", "linux")
    with pytest.raises(ShadeLabError) as exc:
        context.create_headless_context()
    assert str(exc.value).startswith("cannot create a headless OpenGL context (EGL: egl: no "
                                     "device; native GLX: (standalone) XOpenDisplay: cannot "
                                     "open display); on Linux install")
    monkeypatch.setattr(context.sys, "platform", "darwin")  # no EGL there: CGL only
    assert context.backend_order() == ["native"] and context.native_name() == "CGL"
    monkeypatch.setenv("SHADELAB_GL", "egl")
    assert context.backend_order() == ["egl"]


def test_the_bench_machine_block_names_the_backend():
    from shadelab.cli.bench import machine

    info = machine()
    assert info["gl_backend"] in ("egl", "native (GLX)") or \
        info["gl_renderer"].startswith("unavailable")


def _stages() -> dict[str, list[Path]]:
    programs: dict[str, list[Path]] = {}
    for path in sorted(shaders_dir().glob("*.*")):
        if path.suffix in (".vert", ".frag", ".geom"):
            programs.setdefault(path.stem, []).append(path)
    return programs


def test_every_shader_declares_glsl_410_core_or_lower():
    stages = [p for paths in _stages().values() for p in paths]
    assert len(stages) >= 20
    for path in stages:
        first = path.read_text(encoding="utf-8").lstrip().splitlines()[0]
        match = re.fullmatch(r"#version (\d+)( core)?", first.strip())
        assert match, f"{path.name}: first line {first!r} is not '#version N [core]'"
        assert int(match.group(1)) <= MAX_GLSL, f"{path.name}: {first} needs more than GL 4.1"
    for path in (shaders_dir() / "include").glob("*.glsl"):
        assert "#version" not in path.read_text(encoding="utf-8"), f"{path.name}: an include"


@pytest.mark.gl
def test_every_program_compiles(gl_ctx):
    from shadelab.gl.programs import load_program
    from shadelab.raster.renderer import Renderer
    from shadelab.scene.preset import load_preset

    lights = load_preset("multi-lights").lights
    defines = Renderer.light_defines(Renderer.light_signature_of(lights, "blinn"))
    names = sorted(_stages())
    for name in names:
        program = load_program(gl_ctx, name, defines)
        program.release()
    assert {"flat", "gouraud", "phong", "shadow_volume", "radiosity"} <= set(names)
