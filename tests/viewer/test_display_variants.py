"""The display pass compiled per (mode, tone map, clipping) shows what the one program deciding
by uniforms showed, byte for byte (shaders/display.frag; llvmpipe ran every branch under masks)."""

from __future__ import annotations

import itertools

import moderngl
import numpy as np
import pytest

from shadelab.gl.programs import load_program, set_uniform
from shadelab.ui.viewport import Viewport

pytestmark = pytest.mark.gl


def _uniform_program_image(ctx, vp, pane, other, exposure, tonemap, clipping) -> np.ndarray:
    """The display pass as it was: one program, the uniforms deciding every branch."""
    program = load_program(ctx, "display")
    vao = ctx.vertex_array(program, [])
    try:
        pane.display_fbo.use()
        ctx.enable_only(moderngl.NOTHING)
        pane.target.color.use(0)
        (other or pane).target.color.use(1)
        for name, value in (("t_image", 0), ("t_other", 1), ("u_mode", int(other is not None)),
                            ("u_exposure", exposure), ("u_diff_scale", 0.05),
                            ("u_tonemap", int(tonemap == "reinhard")),
                            ("u_clipping", int(clipping))):
            set_uniform(program, name, value)
        vao.render(moderngl.TRIANGLES, vertices=3)
        vp.restore()
        return vp.read_display("main")
    finally:
        vao.release()
        program.release()


def test_each_display_variant_matches_the_uniform_program(gl_ctx, np_rng):
    vp = Viewport(gl_ctx)
    try:
        size = (37, 23)
        pane, other = vp.pane("main", size), vp.pane("other", size)
        hdr = np_rng.uniform(0.0, 1.6, (size[1], size[0], 4)).astype("f4")
        hdr[:3, :3] = 0.0                                  # the sRGB curve's linear toe
        hdr[3:6, :3] = 0.002
        pane.target.color.write(hdr.tobytes())
        other.target.color.write(np_rng.uniform(0.0, 1.6, hdr.shape).astype("f4").tobytes())
        for compare, tonemap, clipping in itertools.product((False, True), ("clamp", "reinhard"),
                                                            (False, True)):
            second = other if compare else None
            for exposure in (1.0, 0.7):
                shown = vp.present(pane, exposure, other=second, tonemap=tonemap,
                                   clipping=clipping)
                assert shown is pane.display
                new = vp.read_display("main")
                old = _uniform_program_image(gl_ctx, vp, pane, second, exposure, tonemap,
                                             clipping)
                np.testing.assert_array_equal(new, old, err_msg=str((compare, tonemap,
                                                                     clipping, exposure)))
        assert len(vp._display_variants) == 8
    finally:
        vp.release()
