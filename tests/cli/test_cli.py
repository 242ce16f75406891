"""The command-line contract of ARCHITECTURE.md §3 for render, presets and validate."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from shadelab.cli import main
from shadelab.scene.preset import list_presets


@pytest.mark.gl
def test_render_writes_png_and_linear_npy(tmp_path):
    png, npy = tmp_path / "c.png", tmp_path / "c.npy"
    assert main(["render", "cornell", "-o", str(png), "--npy", str(npy), "--size", "40x30",
                 "--shading", "gouraud"]) == 0
    image = np.load(npy)
    assert image.dtype == np.float32 and image.shape == (30, 40, 3)
    srgb = np.asarray(Image.open(png))
    assert srgb.shape == (30, 40, 3)
    # Row 0 is the top: the ceiling light (emission 20.7, 10.9, 2.8) is in the upper half.
    brightest_row = np.unravel_index(np.argmax(image[..., 0]), image.shape[:2])[0]
    assert brightest_row < 15
    np.testing.assert_allclose(image.max(axis=(0, 1)), [20.71, 10.85, 2.77], rtol=1e-5)


@pytest.mark.gl
def test_set_changes_the_image_as_the_equation_says(tmp_path):
    """Halving the white walls' kd halves their radiance (ka = 0, one light, no specular)."""
    a, b = tmp_path / "a.npy", tmp_path / "b.npy"
    base = ["--size", "32x32", "--shading", "phong"]
    assert main(["render", "cornell", "-o", str(tmp_path / "a.png"), "--npy", str(a), *base]) == 0
    assert main(["render", "cornell", "-o", str(tmp_path / "b.png"), "--npy", str(b), *base,
                 "--set", "materials.white.kd=0.5"]) == 0
    ia, ib = np.load(a), np.load(b)
    floor = (slice(28, 31), slice(14, 18))  # the white floor near the bottom middle
    np.testing.assert_allclose(ib[floor], 0.5 * ia[floor], rtol=1e-5)


def test_presets_lists_every_preset(capsys):
    assert main(["presets"]) == 0
    out = capsys.readouterr().out
    for name in list_presets():
        assert name in out


def test_validate_reports_counts(capsys):
    assert main(["validate", "cornell"]) == 0
    assert "19 objects, 38 triangles, 1 lights" in capsys.readouterr().out


def test_python_dash_m_app_is_the_same_command():
    out = subprocess.run([sys.executable, "-m", "shadelab", "validate", "sphere-shading"],
                         capture_output=True, text=True)
    assert out.returncode == 0 and "ok sphere-shading" in out.stdout
    bad = subprocess.run([sys.executable, "-m", "shadelab", "validate", "nope"],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stderr.startswith("shadelab: error: unknown preset")
    assert "Traceback" not in bad.stderr


def test_no_egl_gives_one_line_with_what_to_install(tmp_path):
    env = {**__import__("os").environ, "SHADELAB_LIBEGL": str(tmp_path / "libEGL-missing.so")}
    out = subprocess.run([sys.executable, "-m", "shadelab", "render", "cornell", "-o",
                          str(tmp_path / "x.png"), "--size", "8x8"],
                         capture_output=True, text=True, env=env)
    assert out.returncode == 2
    assert out.stderr.count("\n") == 1 and "Traceback" not in out.stderr
    assert "EGL" in out.stderr and "apt-get install libegl1 libgl1-mesa-dri" in out.stderr
    assert not (tmp_path / "x.png").exists()


@pytest.mark.gl
def test_releasing_a_render_target_leaves_no_gl_error(gl_ctx):
    """Creating a framebuffer after a bound one was released must not raise a GL error
    (moderngl re-binds the previous framebuffer; the anchor keeps that one alive)."""
    from shadelab.gl.target import RenderTarget

    _ = gl_ctx.error
    target = RenderTarget(gl_ctx, (8, 8))
    target.clear()
    target.release()
    gl_ctx.simple_framebuffer((4, 4)).release()
    assert gl_ctx.error == "GL_NO_ERROR"


def test_warm_compiles_every_offline_renderer(capsys):
    """`shadelab warm` (run by `make install`) reaches each CPU renderer's kernels."""
    assert main(["warm"]) == 0
    err = capsys.readouterr().err
    for name in ("whitted", "path tracer", "radiosity"):
        assert f"warmed {name}" in err


@pytest.mark.parametrize("kind, code", [(KeyboardInterrupt, 130), (SystemExit, None)])
def test_ctrl_c_inside_a_numba_kernel_is_an_interrupt(monkeypatch, capsys, kind, code):
    """A Ctrl+C landing inside a numba kernel surfaces as SystemErrors around the
    KeyboardInterrupt: still exit 130 and one line; any other SystemError propagates."""
    import shadelab.cli.render as render_cli

    def interrupted(args):
        try:
            raise kind()
        except BaseException as inner:
            try:
                raise SystemError("returned a result with an exception set") from inner
            except SystemError as outer:
                raise SystemError("returned a result with an exception set") from outer

    monkeypatch.setattr(render_cli, "run_presets", interrupted)
    if code is None:
        with pytest.raises(SystemError):
            main(["presets"])
        return
    assert main(["presets"]) == code
    assert capsys.readouterr().err == "shadelab: interrupted\n"


def test_the_command_table_names_every_subcommand_of_the_parser():
    """main() imports only the module of the command asked for (cli.COMMANDS): the table
    must name each subcommand the modules add, and each command's own parser is the same."""
    from shadelab import cli

    full = cli.build_parser()
    choices = full._subparsers._group_actions[0].choices  # noqa: SLF001
    assert set(choices) == set(cli.COMMANDS)
    assert set(cli.COMMANDS.values()) == set(cli.COMMAND_MODULES)
    for command in cli.COMMANDS:
        one = cli.build_parser(command)
        own = one._subparsers._group_actions[0].choices  # noqa: SLF001
        assert command in own
        assert own[command].format_help() == choices[command].format_help()
