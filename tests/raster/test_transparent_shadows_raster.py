"""kt-filtered shadows in the raster (issue 10, item 7): stencil shadow volumes with
transparent casters scale S_i by the casters' transmittance instead of blocking the light.

The oracle is the ray tracer's own kt-filtered shadow ray (``TraceContext.shadow_transmittance``:
the product of kt Ot per surface crossed, 0 at an opaque caster) from each floor point the
camera sees; the GL side's S_i is read off three frames, S = (shadowed - ambient) / (lit -
ambient) per channel, on floor pixels (flat: no terminator fade).
"""

from __future__ import annotations

import numpy as np
import pytest
from test_shadows import SIZE, pixel_surfaces

from shadelab.raster.shadows import FILTER_SLOTS
from shadelab.raytrace.surface import TraceContext
from shadelab.scene import load_preset
from shadelab.shading.reference import shadow_filter

pytestmark = pytest.mark.gl


def _gl_shadow_factor(scene) -> tuple[np.ndarray, np.ndarray]:
    """(P, 3) S_i of light 0 read off the GL frames at P floor pixels, and their rows in
    ``pixel_surfaces(scene, 0)``."""
    from shadelab.raster.offscreen import render_image

    scene.render.shadows = "volumes"
    shadowed = render_image(scene, SIZE).reshape(-1, 3).astype(np.float64)
    scene.render.shadows = "none"
    lit = render_image(scene, SIZE).reshape(-1, 3).astype(np.float64)
    scene.lights[0].enabled = False
    ambient = render_image(scene, SIZE).reshape(-1, 3).astype(np.float64)
    scene.lights[0].enabled = True
    scene.render.shadows = "volumes"
    ray, _position, _normal, _ng = pixel_surfaces(scene, 0)
    term = lit[ray] - ambient[ray]
    keep = term.min(axis=1) > 0.02                    # the light's term is there to divide
    return (shadowed[ray][keep] - ambient[ray][keep]) / term[keep], np.flatnonzero(keep)


def _oracle(scene, rows: np.ndarray) -> np.ndarray:
    """(P, 3) the ray tracer's kt-filtered S_i from the floor points the camera sees."""
    _, position, normal, _ = pixel_surfaces(scene, 0)
    p, n = position[rows], normal[rows]
    light = np.asarray(scene.lights[0].position, dtype=np.float64)
    delta = light - p
    distance = np.linalg.norm(delta, axis=1)
    ctx = TraceContext(scene)
    origin = p + ctx.eps * n
    return ctx.shadow_transmittance(origin, delta / distance[:, None], distance - ctx.eps)


def _agree(gl: np.ndarray, oracle: np.ndarray) -> float:
    return float(np.mean(np.abs(gl - oracle).max(axis=1) < 2e-3))


def test_panes_filter_the_floor_shadow_as_the_ray_tracer_does(gl_ctx):
    """transparency preset: two interpolated panes (S x kt), a filtered one (S x kt Ot) and
    where they overlap the product (the sphere's shadow, 0, lies behind the panes): GL ==
    oracle on >= 98 % of the floor pixels (the rest are shadow edges), each class present."""
    scene = load_preset("transparency")
    gl, rows = _gl_shadow_factor(scene)
    oracle = _oracle(scene, rows)
    assert len(rows) > 5000
    assert _agree(gl, oracle) >= 0.98
    blue, green, smoke = (shadow_filter(scene.materials[m])
                          for m in ("interpolated", "filtered", "smoke"))
    for want in (np.ones(3), blue, green, smoke, blue * green):
        close = np.abs(oracle - want).max(axis=1) < 1e-9
        assert close.sum() > 30, want                     # the class is on the floor ...
        assert _agree(gl[close], oracle[close]) >= 0.97   # ... and the raster has it


def test_a_closed_glass_sphere_filters_twice(gl_ctx):
    """A closed transparent caster: the shadow ray enters and leaves it, S = (kt Ot)^2 (the
    ray tracer's count); the panes removed so only the sphere casts."""
    scene = load_preset("transparency", [
        "materials.orange.kt=0.8", "materials.orange.Ot=[1.0,0.5,0.25]",
        "materials.orange.transparency=filtered"])
    scene.objects = scene.objects[:2]                    # floor and sphere
    gl, rows = _gl_shadow_factor(scene)
    oracle = _oracle(scene, rows)
    squared = (0.8 * np.array([1.0, 0.5, 0.25])) ** 2
    inside = np.abs(oracle - squared).max(axis=1) < 1e-9
    assert inside.sum() > 100
    np.testing.assert_allclose(np.median(gl[inside], axis=0), squared, atol=1e-3)
    assert _agree(gl, oracle) >= 0.98


def test_transparent_casters_past_the_slots_cast_no_shadow(gl_ctx):
    """Only FILTER_SLOTS transparent casters per light are filtered (stencil bits 4..7);
    the rest let the light through (S = 1), never a hard black shadow."""
    assert FILTER_SLOTS == 4
    scene = load_preset("transparency")
    pane = scene.objects[2]
    from dataclasses import replace

    scene.objects = scene.objects[:1] + [
        replace(pane, name=f"pane {i}", translate=(pane.translate[0], pane.translate[1],
                                                   pane.translate[2] + 0.01 * i))
        for i in range(FILTER_SLOTS + 1)]
    gl, _rows = _gl_shadow_factor(scene)
    kt = shadow_filter(scene.materials[pane.material])
    # under all five panes: four filter (kt^4), the fifth lets the light through
    deepest = np.abs(gl - kt ** FILTER_SLOTS).max(axis=1) < 2e-3
    assert deepest.sum() > 100
    assert np.abs(gl - kt ** (FILTER_SLOTS + 1)).max(axis=1).min() > 1e-3
    assert gl.min() > kt.min() ** FILTER_SLOTS - 2e-3


def _probe_against_gpu(scene, size, pixels):
    from shadelab.lab.probe import probe
    from shadelab.raster.offscreen import render_image

    image = render_image(scene, size)
    out = []
    for x, y in pixels:
        result = probe(scene, size, (x, y))
        assert result is not None
        np.testing.assert_allclose(result.reference, image[y, x], rtol=1e-3, atol=1e-4)
        out.append(result)
    return out


@pytest.mark.parametrize("shading", ["flat", "gouraud", "phong"])
def test_the_probe_reports_the_stencil_s_i_and_matches_the_gpu(gl_ctx, shading):
    """With shadows on, the probe's S_i is the shadow volumes' (1 lit, 0 behind the box,
    kt-filtered behind a pane) and its reference value is the pixel the GPU drew."""
    size = (160, 120)
    scene = load_preset("transparency", ["render.shadows=volumes", f"render.shading={shading}"])
    ray, position, _n, _g = pixel_surfaces(scene, 0)
    gl, rows = _gl_shadow_factor(scene)
    oracle = _oracle(scene, rows)
    green = shadow_filter(scene.materials["filtered"])
    picks = {}
    for label, want in (("lit", np.ones(3)), ("green", green)):
        close = np.flatnonzero((np.abs(oracle - want).max(axis=1) < 1e-9)
                               & (np.abs(gl - want).max(axis=1) < 1e-4))
        r = int(ray[rows[close[len(close) // 2]]])
        picks[label] = (r % size[0], r // size[0])
    lit, filtered = _probe_against_gpu(scene, size, [picks["lit"], picks["green"]])
    assert float(np.asarray(lit.terms.lights[0].shadow).min()) == 1.0
    np.testing.assert_allclose(filtered.terms.lights[0].shadow, green, rtol=1e-12)
