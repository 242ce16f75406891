"""Textures and bump maps in the Whitted tracer against the raster's ``*_tex`` programs."""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.raytrace.surface import TraceContext
from shadelab.raytrace.whitted import render_raytraced
from shadelab.scene.camera import primary_rays
from shadelab.scene.preset import load_preset
from shadelab.shading.conventions import to_srgb8
from shadelab.shading.surface_detail import (
    checker,
    height_gradient_bumps,
    sample_linear_repeat,
    triangle_tangents,
)

SIZE = (96, 80)


def _same_3x3(ids: np.ndarray) -> np.ndarray:
    h, w = ids.shape
    padded = np.pad(ids, 1, mode="edge")
    same = np.ones_like(ids, dtype=bool)
    for dy in (0, 1, 2):
        for dx in (0, 1, 2):
            same &= padded[dy:dy + h, dx:dx + w] == ids
    return same


def _masks(scene, size):
    """Per pixel: the object seen (-1: none), and True away from silhouettes and from the
    checker's cell edges (the pixel and its 8 neighbours see the same object and cell)."""
    ctx = TraceContext(scene)
    o, d = primary_rays(scene.camera, *size)
    hits = ctx.accel.intersect(o.reshape(-1, 3), d.reshape(-1, 3))
    tri = np.maximum(hits.tri, 0)
    obj = np.where(hits.hit, ctx.geometry.object_index[tri], -1)
    uv = ctx.detail.hit_uv(tri, hits.u, hits.v)
    cells = np.zeros(len(obj), np.int64)
    for i, o_ in enumerate(scene.objects):
        m = scene.materials[o_.material]
        if m.texture == "checker":
            c = np.floor(uv * m.texture_scale).astype(np.int64)
            cells = np.where(obj == i, (c[:, 0] + c[:, 1]) % 2, cells)
    key = (obj * 2 + cells).reshape(size[1], size[0])
    return obj.reshape(size[1], size[0]), _same_3x3(key)


def test_triangle_tangents_and_checker_closed_forms():
    corners = np.array([[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 3.0, 0.0]]])
    uvs = np.array([[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]])
    dpdu, dpdv = triangle_tangents(corners, uvs)
    assert np.allclose(dpdu, [[2.0, 0.0, 0.0]]) and np.allclose(dpdv, [[0.0, 3.0, 0.0]])
    flat = triangle_tangents(corners, np.zeros((1, 3, 2)))
    assert not np.any(flat[0]) and not np.any(flat[1])
    od = checker(np.array([[0.05, 0.05], [0.15, 0.05], [0.15, 0.15]]), 10.0, (1, 1, 1), (0, 0, 0))
    assert np.array_equal(od[:, 0], [1.0, 0.0, 1.0])
    g = height_gradient_bumps(np.array([[0.0, 0.25]]), 1.0)
    assert np.allclose(g, [[np.pi, 0.0]])


def test_sampler_is_gl_repeat_linear_with_texel_centres():
    image = np.arange(8.0).reshape(2, 4)  # row 0 at v = 0
    p = np.array([[0.125, 0.25], [0.25, 0.25], [1.125, 1.25], [0.0, 0.25]])
    assert np.allclose(sample_linear_repeat(image, p), [0.0, 0.5, 0.0, 1.5])


@pytest.mark.gl
def test_depth0_textured_preset_equals_raster_phong(gl_ctx):
    """surface-detail: Whitted at depth 0 without shadows is the Phong raster within 1/255
    away from silhouettes and checker cell edges: checker, image texture + height map, bumps."""
    from shadelab.raster.offscreen import render_image

    scene = load_preset("surface-detail")
    raster = render_image(scene, SIZE, "phong")
    traced = render_raytraced(scene, SIZE, depth=0, spp=1, shadows=False)
    obj, mask = _masks(scene, SIZE)
    exposure = scene.render.exposure
    diff = np.abs(to_srgb8(raster, exposure).astype(int) - to_srgb8(traced, exposure).astype(int))
    names = [o.name for o in scene.objects]
    for name in ("floor", "brick wall", "bumpy sphere"):
        sel = mask & (obj == names.index(name))
        assert sel.sum() > 200, name
        assert diff[sel].max() <= 1, (name, diff[sel].max())


def _bumpy_mirror(kr: float = 0.8, bump_scale: float = 0.08):
    return load_preset("surface-detail", [f"materials.bumpy.kr={kr}",
                                          f"materials.bumpy.bump_scale={bump_scale}"])


def _sphere_pixel(scene, size):
    obj, inside = _masks(scene, size)
    ys, xs = np.nonzero((obj == 2) & inside)
    k = len(ys) // 3
    return int(xs[k]), int(ys[k])


def test_mirror_rays_leave_about_the_bumped_normal():
    """A bumped mirror sphere: the ray tree's reflected ray is R = D - 2 (D.N') N' with N' the
    bumped normal the local model shades with (the numpy surface-detail lookups), not the
    smooth normal; without a bump the two coincide."""
    from shadelab.raytrace.tree import pixel_ray, trace_pixel_tree

    size = (96, 80)
    for scale, bent in ((0.08, True), (0.0, False)):
        scene = _bumpy_mirror(bump_scale=scale)
        x, y = _sphere_pixel(scene, size)
        ctx = TraceContext(scene)
        root = trace_pixel_tree(scene, size, x, y, depth=1, ctx=ctx)
        assert root.object == 2
        origin, d = pixel_ray(scene, size, x, y)
        hits = ctx.accel.intersect(origin[None], d[None])
        surf = ctx.surface(origin[None], d[None], hits)
        m = ctx.material_ids(surf)
        smooth = surf.normal[0]
        if scale:
            _, bumped = ctx.detail.od_and_normal(int(m[0]), hits.tri, hits.u, hits.v,
                                                  surf.normal)
            n = bumped[0]
        else:
            n = smooth
        want = d - 2.0 * np.dot(d, n) * n
        reflected = [c for c in root.children if c.kind == "reflected"]
        assert len(reflected) == 1
        np.testing.assert_allclose(reflected[0].direction, want, atol=1e-9)
        mirror = d - 2.0 * np.dot(d, smooth) * smooth
        assert (np.degrees(np.arccos(np.clip(np.dot(want, mirror), -1, 1))) > 0.5) == bent


def _last_image(scene, size, ctx):
    from shadelab.raytrace.whitted import iter_raytrace

    image = None
    for step in iter_raytrace(scene, size, depth=2, ctx=ctx):
        image = step.image
    return image


def test_bumped_reflections_are_the_same_in_the_batch_kernels_and_the_numpy_path():
    """Whitted's batched numba path and the numpy path reflect about the same bumped normals:
    equal images (1e-6) at depth 2, and the bumps change the mirrored image."""
    size = (48, 40)
    scene = _bumpy_mirror()
    numba = _last_image(scene, size, TraceContext(scene))
    numpy = _last_image(scene, size, TraceContext(scene, local="numpy"))
    np.testing.assert_allclose(numba, numpy, atol=1e-6)
    flat = render_raytraced(_bumpy_mirror(bump_scale=0.0), size, depth=2)
    obj, _inside = _masks(scene, size)
    assert np.abs(numba - flat)[obj == 2].max() > 0.02
