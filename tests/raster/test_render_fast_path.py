"""The raster frame's fast path (issue 13.1): premultiplied uniforms, the uniform cache, merged
draws of one material. Same images as the uniform-driven programs drawn object by object, and a
warm renderer follows every change a fresh one sees."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import shadelab.raster.renderer as renderer_module
from shadelab.gl.programs import UniformCache, load_program
from shadelab.gl.target import RenderTarget
from shadelab.raster.renderer import Renderer, _material_runs
from shadelab.scene.preset import load_preset

SIZE = (160, 120)
PRESETS = ["cornell", "colored-lights", "multi-lights", "spotlight", "lecture", "shadows",
           "transparency", "surface-detail"]


def _render(ctx, scene, shading, renderer=None):
    own = renderer is None
    renderer = renderer or Renderer(ctx)
    target = RenderTarget(ctx, SIZE)
    try:
        renderer.render(scene, target, shading)
        return target.read()
    finally:
        target.release()
        if own:
            renderer.release()


@pytest.mark.gl
@pytest.mark.parametrize("shading", ["flat", "gouraud", "phong"])
@pytest.mark.parametrize("preset", PRESETS)
def test_premultiplied_and_merged_draws_match_the_uniform_driven_path(gl_ctx, monkeypatch,
                                                                      preset, shading):
    fast = _render(gl_ctx, load_preset(preset), shading)
    # the uniform-driven programs (u_ka, u_light_Ip ... read per fragment), one draw per object
    monkeypatch.setattr(renderer_module, "PREMULTIPLIED", {})
    monkeypatch.setattr(renderer_module, "_material_runs", lambda meshes: [[g] for g in meshes])
    slow = _render(gl_ctx, load_preset(preset), shading)
    # the same equation with the uniform factors multiplied on the CPU: float rounding only
    np.testing.assert_allclose(fast, slow, rtol=1e-4, atol=2e-5)


@pytest.mark.gl
def test_a_warm_renderer_follows_every_change(gl_ctx):
    scene = load_preset("colored-lights")
    warm = Renderer(gl_ctx)
    try:
        _render(gl_ctx, scene, "phong", warm)
        edits = [
            lambda s: setattr(s.materials[s.objects[0].material], "kd", 0.25),
            lambda s: setattr(s.materials[s.objects[0].material], "Od", (0.1, 0.9, 0.3)),
            lambda s: setattr(s.lights[0], "position", tuple(np.asarray(s.lights[0].position)
                                                              + 0.5)),
            lambda s: setattr(s.lights[0], "Ip", (3.0, 0.5, 0.25)),
            lambda s: setattr(s, "Ia", (0.3, 0.2, 0.1)),
            lambda s: setattr(s.camera, "eye", tuple(np.asarray(s.camera.eye) * 1.1)),
            lambda s: setattr(s.objects[0], "translate", (0.2, 0.0, 0.0)),
            lambda s: s.objects.append(dataclasses.replace(s.objects[-1], name="copy",
                                                           translate=(0.5, 0.5, 0.5))),
            lambda s: s.objects.pop(0),
        ]
        for edit in edits:
            edit(scene)
            for shading in ("phong", "gouraud"):
                np.testing.assert_array_equal(_render(gl_ctx, scene, shading, warm),
                                              _render(gl_ctx, scene, shading))
    finally:
        warm.release()


def test_material_runs_keep_the_order_and_cut_where_the_material_changes():
    class Mesh:
        def __init__(self, material):
            self.mesh = type("M", (), {"material": material})()

    meshes = [Mesh(m) for m in "aabaacb"]
    runs = _material_runs(meshes)
    assert [[g.mesh.material for g in run] for run in runs] == [["a", "a"], ["b"], ["a", "a"],
                                                                ["c"], ["b"]]
    assert [g for run in runs for g in run] == meshes


@pytest.mark.gl
def test_uniform_cache_writes_only_what_changed(gl_ctx):
    program = load_program(gl_ctx, "bare_phong")
    try:
        cache = UniformCache(program)
        assert "u_n" in cache and "in_position" not in cache and "u_missing" not in cache
        cache.write("u_n", np.float32(10.0).tobytes())
        assert program["u_n"].value == pytest.approx(10.0)
        program["u_n"].value = 3.0          # a write behind the cache's back ...
        cache.write("u_n", np.float32(10.0).tobytes())
        assert program["u_n"].value == pytest.approx(3.0)  # ... is not seen: same bytes, no write
        cache.forget("u_n")
        cache.write("u_n", np.float32(10.0).tobytes())
        assert program["u_n"].value == pytest.approx(10.0)
        cache.write("u_missing", b"\0\0\0\0")  # optimized away: ignored
    finally:
        program.release()
