"""Shadow rays are asked first about the casters that take light away: a caster that passes
every channel whole (clear glass, kt Ot = 1) changes no S_i, so rays it alone blocks are not
followed through it. Exact: the images equal those of the walk through every caster."""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.raytrace.accel import embree_available
from shadelab.raytrace.surface import TraceContext
from shadelab.raytrace.whitted import iter_raytrace
from shadelab.scene.preset import load_preset

BACKENDS = ["bvh"] + (["embree"] if embree_available() else [])


def _render(scene, ctx, size=(64, 64)):
    return list(iter_raytrace(scene, size, ctx=ctx))[-1].image


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("local", ["numba", "numpy"])
@pytest.mark.parametrize("overrides", [(), ("materials.glass.kt=0.9",)])
def test_skipping_clear_casters_changes_no_pixel(backend, local, overrides):
    scene = load_preset("cornell-spheres", list(overrides))
    fast = TraceContext(scene, backend, local=local)
    walk = TraceContext(scene, backend, local=local)
    walk.__dict__["_light_takers"] = None   # every caster's blocked ray followed, as before
    assert fast.transparent_casters
    np.testing.assert_array_equal(_render(scene, fast), _render(scene, walk))
    if overrides:   # a glass that takes light: nothing skipped
        assert fast._light_takers is None and fast.shadow_rays == walk.shadow_rays
    else:           # the clear glass is left out: fewer rays followed, same image
        assert fast._light_takers is not None and fast.shadow_rays < walk.shadow_rays


@pytest.mark.parametrize("backend", BACKENDS)
def test_an_occluder_sees_its_subset_of_triangles_only(backend):
    scene = load_preset("cornell-spheres")
    ctx = TraceContext(scene, backend)
    g = ctx.geometry
    glass = np.flatnonzero(np.asarray([ctx.object_material[o] for o in g.object_index])
                           == ctx.object_material[g.object_index[-1]])
    # rays from below each glass triangle's centroid straight up through it
    tri = g.triangles[glass[:50]]
    centre = tri.mean(axis=1)
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    origins, dirs = centre + 0.5 * normal, -normal          # outside, pointing at the face
    tmax = np.full(len(origins), 1.0)
    everything = np.arange(g.count)
    others = np.setdiff1d(everything, glass)
    assert ctx.accel.occluder(everything).occluded(origins, dirs, tmax).all()
    assert not ctx.accel.occluder(others).occluded(origins, dirs, tmax).any()
    assert not ctx.accel.occluder(others[:0]).occluded(origins, dirs, tmax).any()
