"""kt-filtered shadows in Whitted: S_i = product of kt Ot over the transparent casters crossed.

A floor under a point light, with panes between them: the shadowed floor's direct term is
the unshadowed one times kt Ot per pane (kt alone for the interpolated model), 0 behind an
opaque pane; scenes without a transparent caster keep binary S_i.
"""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.raytrace.surface import TraceContext
from shadelab.raytrace.tree import trace_pixel_tree
from shadelab.raytrace.whitted import trace_batch
from shadelab.scene.model import Camera, Light, Material, Object, RenderSettings, Scene
from shadelab.scene.preset import load_preset

KT, OT = 0.5, (1.0, 0.5, 0.25)
EYE = np.array([4.0, 1.0, 0.3])
# Floor points under the panes (shadowed: the panes' footprint from the light is |x|, |z| <
# 1.67) and two outside it (lit)
SHADOWED = np.array([[0.2, 0.0, 0.1], [-0.6, 0.0, 0.5], [0.9, 0.0, -1.1]])
LIT = np.array([[3.0, 0.0, 2.5], [-2.5, 0.0, -3.0]])


def _pane(y: float, material: str) -> Object:
    return Object(shape="quad", material=material,
                  vertices=[[-1, y, -1], [1, y, -1], [1, y, 1], [-1, y, 1]])


def _scene(panes: list[tuple[float, str]]) -> Scene:
    materials = {
        "floor": Material(ka=0.5, kd=0.7, ks=0.4, n=20.0, Od=(0.8, 0.7, 0.6)),
        "filtered": Material(kd=0.3, Od=(0.2, 0.9, 0.4), kt=KT, Ot=OT, transparency="filtered"),
        "interpolated": Material(kd=0.3, kt=KT, Ot=OT, transparency="interpolated"),
        "opaque": Material(kd=0.3),
    }
    objects = [Object(shape="plane", material="floor", size=12.0)]
    objects += [_pane(y, m) for y, m in panes]
    return Scene(Ia=(0.0, 0.0, 0.0), camera=Camera(eye=tuple(EYE), target=(0.0, 0.0, 0.0)),
                 lights=[Light(kind="point", position=(0.0, 5.0, 0.0), Ip=(1.0, 0.9, 0.8))],
                 materials=materials, objects=objects,
                 render=RenderSettings(background=(0.0, 0.0, 0.0)))


def _direct(scene: Scene, local: str, shadows: bool = True) -> np.ndarray:
    """Radiance (depth 0) seen from EYE at the floor points SHADOWED then LIT."""
    ctx = TraceContext(scene, "bvh", shadows=shadows, local=local)
    targets = np.concatenate([SHADOWED, LIT])
    dirs = targets - EYE
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    return trace_batch(ctx, np.repeat(EYE[None], len(dirs), axis=0), dirs, 0, False)


@pytest.mark.parametrize("local", ["numba", "numpy"])
@pytest.mark.parametrize("panes, factor", [
    ([(2.0, "filtered")], KT * np.array(OT)),
    ([(2.0, "filtered"), (3.0, "filtered")], (KT * np.array(OT)) ** 2),
    ([(2.0, "interpolated")], np.full(3, KT)),
    ([(2.0, "filtered"), (3.0, "opaque")], np.zeros(3)),
    ([(2.0, "opaque")], np.zeros(3)),
])
def test_shadow_is_kt_ot_times_the_lit_direct_term(local, panes, factor):
    scene = _scene(panes)
    shadowed = _direct(scene, local)
    unshadowed = _direct(scene, local, shadows=False)
    n = len(SHADOWED)
    assert unshadowed.min() > 1e-3  # Ia = 0: every pixel is the direct term
    np.testing.assert_allclose(shadowed[:n], factor * unshadowed[:n], rtol=0, atol=1e-9)
    np.testing.assert_array_equal(shadowed[n:], unshadowed[n:])


def test_numba_and_numpy_paths_agree_with_transparent_casters():
    scene = _scene([(2.0, "filtered"), (3.0, "interpolated")])
    np.testing.assert_allclose(_direct(scene, "numba"), _direct(scene, "numpy"),
                               rtol=0, atol=1e-9)


def test_opaque_scene_keeps_binary_shadow_factors():
    ctx = TraceContext(_scene([(2.0, "opaque")]), "bvh")
    assert not ctx.transparent_casters
    assert TraceContext(_scene([(2.0, "filtered")]), "bvh").transparent_casters
    targets = np.concatenate([SHADOWED, LIT])
    dirs = targets - EYE
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    origins = np.repeat(EYE[None], len(dirs), axis=0)
    hits = ctx.accel.intersect(origins, dirs)
    surf = ctx.surface(origins, dirs, hits)
    for local in (True, False):
        ctx.kernels = local
        (s,) = ctx.shadow_factors(surf)
        assert s.shape == (len(dirs),)
        np.testing.assert_array_equal(s, [0, 0, 0, 1, 1])


def test_non_caster_pane_lets_light_through():
    scene = _scene([(2.0, "opaque")])
    scene.objects[1].cast_shadows = False
    np.testing.assert_array_equal(_direct(scene, "numba"), _direct(scene, "numba", False))


def test_ray_tree_reports_the_filtered_shadow():
    scene = _scene([(2.0, "filtered")])
    scene.camera = Camera(eye=(0.0, 1.0, 6.0), target=(0.0, 0.0, 0.0))
    ctx = TraceContext(scene, "bvh", local="numpy")
    # any pixel whose floor point lies in the pane's shadow: the tree's S is max(kt Ot)
    tree = trace_pixel_tree(scene, (64, 48), 32, 23, depth=0, ctx=ctx)
    assert np.abs(tree.end[[0, 2]]).max() < 1.0
    shadows = [c.shadow for c in tree.children if c.kind == "shadow"]
    assert shadows == [pytest.approx(KT * max(OT))]


def test_one_pass_per_channel_kernel_equals_a_pass_per_channel():
    """kernels.local_shade_into3 (S_i per channel in one pass) == three local_shade_into
    passes with each channel's S_i, bit for bit, on random points, materials and S."""
    from shadelab.shading import kernels

    scene = load_preset("shadows-colored")
    ctx = TraceContext(scene)
    rng = np.random.default_rng(5)
    n, lights = 500, len(ctx.lights)
    position = rng.uniform(-2, 2, (n, 3))
    normal = rng.normal(size=(n, 3))
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    mat = rng.integers(0, len(ctx.materials), n)
    shadow = rng.uniform(0, 1, (lights, n, 3)) * (rng.uniform(size=(lights, n, 1)) > 0.3)
    one = np.empty((n, 3))
    kernels.local_shade_into3(one, position, normal, d, mat, ctx.material_table,
                              ctx.light_table, ctx.Ia, False, shadow, 1.0)
    three = np.empty((n, 3))
    for c in range(3):
        part = np.empty((n, 3))
        kernels.local_shade_into(part, position, normal, d, mat, ctx.material_table,
                                 ctx.light_table, ctx.Ia, False,
                                 np.ascontiguousarray(shadow[..., c]), 1.0)
        three[:, c] = part[:, c]
    np.testing.assert_array_equal(one, three)
