"""The fused path tracer (whole paths in one numba loop, Embree called ray by ray) against
the wavefront it replaces: the same rays from the same Embree build, the same image bit for
bit (issue 19.3)."""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.raytrace import embree_direct, pathtrace
from shadelab.raytrace.accel import EmbreeAccel, embree_available, scene_geometry
from shadelab.raytrace.pathtrace import PathTracer, TileJob, render_pathtraced
from shadelab.scene.preset import load_preset

pytestmark = pytest.mark.skipif(not embree_available(), reason="embreex not installed")


def _both(scene, size, spp, seed, monkeypatch):
    fused = render_pathtraced(scene, size, spp, seed=seed)
    with monkeypatch.context() as patch:
        patch.setattr(pathtrace, "FUSED", False)
        wavefront = render_pathtraced(scene, size, spp, seed=seed)
    return fused, wavefront


def test_direct_embree_answers_as_embreex():
    """rtcIntersect1 / rtcOccluded1 called from numba on our own scene: the triangle, t, u,
    v and the occlusion flags embreex gives for the same float32 rays, bit for bit."""
    import numba as nb

    geometry = scene_geometry(load_preset("cornell-spheres"))
    scene = embree_direct.embree_scene(geometry.triangles)
    assert scene is not None and scene.count == geometry.count > 1000

    @nb.njit
    def trace(fns, o, d, tmax):
        fn_hit, fn_occ, sc = fns
        words, ints, addr = embree_direct.ray_buffer()
        n = len(o)
        tri, t, u, v = np.empty(n, np.int64), np.empty(n), np.empty(n), np.empty(n)
        blocked = np.empty(n, np.bool_)
        for i in range(n):
            tri[i], t[i], u[i], v[i] = embree_direct.intersect1(
                fn_hit, sc, words, ints, addr, o[i, 0], o[i, 1], o[i, 2], d[i, 0], d[i, 1],
                d[i, 2], 1e37)
            blocked[i] = embree_direct.occluded1(fn_occ, sc, words, ints, addr, o[i, 0],
                                                 o[i, 1], o[i, 2], d[i, 0], d[i, 1], d[i, 2],
                                                 tmax[i])
        return tri, t, u, v, blocked

    rng = np.random.default_rng(7)
    n = 4000
    o = rng.uniform([10.0, 10.0, 10.0], [540.0, 540.0, 550.0], (n, 3))
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    tmax = rng.uniform(1.0, 400.0, n)
    fns = (np.uint64(scene.intersect), np.uint64(scene.occluded), np.uint64(scene.scene))
    tri, t, u, v, blocked = trace(fns, o, d, tmax)
    accel = EmbreeAccel(geometry)
    hits = accel.intersect(o, d)
    np.testing.assert_array_equal(tri, hits.tri)
    np.testing.assert_array_equal(t, hits.t)
    np.testing.assert_array_equal(u[tri >= 0], hits.u[tri >= 0])
    np.testing.assert_array_equal(v[tri >= 0], hits.v[tri >= 0])
    np.testing.assert_array_equal(blocked, accel.occluded(o, d, tmax, everything=True))
    assert 0.05 < blocked.mean() < 0.95 and 0.5 < (tri >= 0).mean() < 1.0


@pytest.mark.parametrize("preset, overrides", [
    ("cornell", []),
    ("cornell-spheres", []),                                      # mirror and glass
    ("cornell", ["materials.white.ks=0.4", "materials.white.n=20"]),  # glossy, Phong
    ("cornell", ["materials.white.ks=0.3", "render.specular=blinn"]),  # glossy, Blinn
])
def test_fused_paths_are_the_wavefront_bit_for_bit(preset, overrides, monkeypatch):
    """Every lobe (diffuse, glossy both ways, mirror, glass), several passes per call and
    more than one tile: the fused kernel renders exactly the wavefront's image."""
    scene = load_preset(preset, overrides)
    assert PathTracer(scene).fused_scene() is not None
    fused, wavefront = _both(scene, (24, 18), 6, 11, monkeypatch)
    np.testing.assert_array_equal(fused, wavefront)
    assert fused.mean() > 0.01


def test_fused_counts_rays_and_primary_hits_as_the_wavefront(monkeypatch):
    scene = load_preset("cornell-spheres")
    job = TileJob(scene, (20, 16), 8, 2, "auto", "numba", "sobol")
    fused = job(0, 3, 11, 4)
    with monkeypatch.context() as patch:
        patch.setattr(pathtrace, "FUSED", False)
        wave = job(0, 3, 11, 4)
    np.testing.assert_array_equal(fused[0], wave[0])
    assert fused[1:] == wave[1:] and fused[1] > 20 * 8 * 4 and 0 < fused[2] <= 20 * 8


@pytest.mark.parametrize("preset, overrides", [
    ("lecture", []),                                     # delta lights: the wavefront
    ("surface-detail", []),                              # textures and bumps
    ("cornell", ["raytrace.sampler=independent"]),       # the sampler it does not draw
])
def test_scenes_the_fused_kernel_leaves_to_the_wavefront(preset, overrides, monkeypatch):
    scene = load_preset(preset, overrides)
    tracer = PathTracer(scene)
    if scene.raytrace.sampler == "sobol":
        assert tracer.fused_scene() is None
    else:
        assert tracer.fused_scene() is not None   # available, but TileJob draws uniforms
        calls = []
        monkeypatch.setattr(PathTracer, "trace_tile", lambda *a: calls.append(a))
        render_pathtraced(scene, (8, 6), 2)
        assert not calls


def test_the_viewport_job_goes_from_a_quarter_size_to_full_size():
    """The path tracer's viewer levels are 1/8, 1/4, full (no half size before the first
    full-resolution sample); ``level_work`` counts a level's samples, so the viewer knows
    when a full pass is on screen; the last image is the full render at the scene's spp."""
    from shadelab.pipelines import registry

    scene = load_preset("cornell", ["raytrace.spp=4"])
    size = (40, 24)
    steps = list(registry.get("pathtrace").viewport_job(scene, size))
    assert [s for s in dict.fromkeys(step.stats["level"] for step in steps)] == [8, 4, 1]
    full = [step for step in steps if step.stats["level"] == 1]
    first = next(step for step in full if step.stats["level_work"] >= size[0] * size[1])
    # the first whole pass: each pixel's Sobol' sample 0, the one-sample image
    np.testing.assert_array_equal(first.image, render_pathtraced(scene, size, 1, seed=1))
    np.testing.assert_array_equal(steps[-1].image, render_pathtraced(scene, size, 4, seed=1))


def test_fused_jobs_hold_more_paths():
    """Whole paths in one call: a small image's passes go together up to 2^18 paths a call
    (a pixel's samples in a row), a large one in tiles of 2^18 paths; the wavefront's rule
    is unchanged."""
    from shadelab.raytrace.pathtrace import FUSED_TILE_PATHS, passes_per_job

    assert FUSED_TILE_PATHS == 1 << 18
    assert passes_per_job((128, 128), 64, fused=True) == 16
    assert passes_per_job((128, 128), 64) == 1
    assert passes_per_job((64, 64), 64, fused=True) == 16
    assert passes_per_job((1280, 800), 64, fused=True) == 1
    assert passes_per_job((256, 256), 3, fused=True) == 1
