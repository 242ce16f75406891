"""Materials with no specular term (ks = 0, or the term switched off) are drawn with the
shading program's diffuse twin, compiled with lighting.glsl's NO_SPECULAR (issue 25: the
lobe's pow was most of a ks = 0 fragment's cost on llvmpipe). The twin must leave every image
as it was, bit for bit: ks Os times the lobe was +0."""

from __future__ import annotations

import numpy as np
import pytest

import shadelab.raster.renderer as renderer_module
from shadelab.gl.target import RenderTarget
from shadelab.raster.renderer import DIFFUSE_SUFFIX, Renderer, diffuse_only
from shadelab.raster.textures import has_surface_detail
from shadelab.scene.model import Material
from shadelab.scene.preset import load_preset
from shadelab.shading.codes import TERM_BITS

SIZE = (160, 120)


def _image(ctx, scene, shading=None, terms_off=0, renderer=None):
    own = renderer is None
    renderer = renderer or Renderer(ctx)
    target = RenderTarget(ctx, SIZE)
    try:
        renderer.render(scene, target, shading, terms_off=terms_off)
        return target.read()
    finally:
        target.release()
        if own:
            renderer.release()


def test_diffuse_only_is_ks_zero_or_the_term_off():
    assert diffuse_only(Material(ks=0.0))
    assert not diffuse_only(Material(ks=0.3))
    assert diffuse_only(Material(ks=0.3), TERM_BITS["specular"])
    assert not diffuse_only(Material(ks=0.3), TERM_BITS["diffuse"])


@pytest.mark.gl
@pytest.mark.parametrize("preset, shading, terms_off", [
    ("cornell", "phong", 0), ("cornell", "gouraud", 0), ("cornell", "flat", 0),
    ("lecture", "phong", 0), ("lecture", "gouraud", 0),
    ("lecture", "phong", TERM_BITS["specular"]),
    ("lecture", "phong", TERM_BITS["shadow"]),
    ("multi-lights", "phong", 0), ("transparency", "phong", 0),
    ("painter-cyclic", "phong", 0), ("surface-detail", "phong", 0),
    ("spotlight", "phong", 0),
])
def test_the_diffuse_twin_keeps_the_image(gl_ctx, monkeypatch, preset, shading, terms_off):
    scene = load_preset(preset)
    monkeypatch.setattr(renderer_module, "DIFFUSE_VARIANTS", False)
    full = _image(gl_ctx, scene, shading, terms_off)
    monkeypatch.setattr(renderer_module, "DIFFUSE_VARIANTS", True)
    renderer = Renderer(gl_ctx)
    try:
        twin = _image(gl_ctx, scene, shading, terms_off, renderer)
        names = [name for variant in renderer._variants.values() for name in variant]
    finally:
        renderer.release()
    if any(diffuse_only(m, terms_off) and not has_surface_detail(m)
           for m in scene.materials.values()):   # the textured programs have no twin
        assert shading + DIFFUSE_SUFFIX in names, "a ks = 0 material is drawn by the twin"
    np.testing.assert_array_equal(twin, full)


@pytest.mark.gl
def test_the_twin_really_leaves_the_lobe_out(gl_ctx):
    """The twin's own output for a shiny material: its highlight is gone (so the renderer
    must give it only materials whose ks is 0)."""
    scene = load_preset("lecture", ["render.shadows=none"])
    renderer = Renderer(gl_ctx)
    try:
        full = _image(gl_ctx, scene, renderer=renderer)
        renderer_module_program_for = renderer.program_for
        renderer.program_for = lambda shading, material: shading + DIFFUSE_SUFFIX
        lobe_left_out = _image(gl_ctx, scene, renderer=renderer)
        renderer.program_for = renderer_module_program_for
    finally:
        renderer.release()
    # the plastic sphere's highlight (ks 0.5, n 60) is white: the twin is darker there
    assert (full - lobe_left_out).max() > 0.2
    assert (lobe_left_out - full).max() <= 1e-6   # the twin only ever removes light


@pytest.mark.gl
def test_a_students_chunk_has_no_twin_compiled(gl_ctx):
    """A replaced lighting chunk knows no NO_SPECULAR: the twin is its own program."""
    from shadelab.resources import shaders_dir
    from shadelab.testing import _includes_replaced

    text = (shaders_dir() / "include" / "lighting.glsl").read_text(encoding="utf-8")
    replaced = text.replace("#ifdef NO_SPECULAR", "#ifdef NO_SUCH_DEFINE")
    scene = load_preset("cornell")
    renderer = Renderer(gl_ctx)
    target = RenderTarget(gl_ctx, SIZE)
    try:
        with _includes_replaced({"lighting": replaced}):
            renderer.render(scene, target, "phong")
            programs = renderer.programs
            assert programs["phong" + DIFFUSE_SUFFIX] is programs["phong"]
    finally:
        target.release()
        renderer.release()
