"""The Whitted ray tracer against closed forms and against the raster.

Tolerances: linear radiance unless stated; raster parity within 1/255 after exposure + sRGB.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from shadelab.cli import main
from shadelab.raytrace.accel import scene_geometry
from shadelab.raytrace.surface import TraceContext, reflect_refract
from shadelab.raytrace.tree import trace_pixel_tree
from shadelab.raytrace.whitted import render_raytraced, trace_batch
from shadelab.scene.camera import primary_rays
from shadelab.scene.model import Camera, Light, Material, Object, RenderSettings, Scene
from shadelab.scene.preset import load_preset
from shadelab.shading.conventions import to_srgb8


def _scene(objects, materials, lights, eye=(0.0, 0.0, 5.0), target=(0.0, 0.0, 0.0),
           background=(0.0, 0.0, 0.0), Ia=(0.0, 0.0, 0.0), fov=40.0) -> Scene:
    return Scene(Ia=Ia, camera=Camera(eye=eye, target=target, fov_y=fov), lights=lights,
                 materials=materials, objects=objects,
                 render=RenderSettings(background=background))


def _edge_mask(scene: Scene, size) -> np.ndarray:
    """True where the pixel and its 8 neighbours all see the same opaque object (or all miss).

    Transparent objects (kt > 0) are left out: the raster blends what lies behind them,
    which the ray tracer only adds at depth >= 1.
    """
    ctx = TraceContext(scene)
    o, d = primary_rays(scene.camera, *size)
    hits = ctx.accel.intersect(o.reshape(-1, 3), d.reshape(-1, 3))
    ids = np.where(hits.hit, ctx.geometry.object_index[np.maximum(hits.tri, 0)], -1)
    ids = ids.reshape(size[1], size[0])
    padded = np.pad(ids, 1, mode="edge")
    same = np.ones_like(ids, dtype=bool)
    for dy in (0, 1, 2):
        for dx in (0, 1, 2):
            same &= padded[dy:dy + size[1], dx:dx + size[0]] == ids
    clear = [i for i, obj in enumerate(scene.objects) if scene.material_of(obj).kt > 0.0]
    return same & ~np.isin(ids, clear)


# ------------------------------------------------------------------ raster parity


@pytest.mark.gl
@pytest.mark.parametrize("preset", ["cornell-spheres", "whitted"])
def test_depth0_without_shadows_equals_raster_phong(gl_ctx, preset):
    """Depth 0, S_i = 1: every pixel away from silhouettes within 1/255 of the Phong raster."""
    from shadelab.raster.offscreen import render_image

    scene = load_preset(preset)
    size = (48, 40)
    raster = render_image(scene, size, "phong")
    traced = render_raytraced(scene, size, depth=0, spp=1, shadows=False)
    mask = _edge_mask(scene, size)
    assert mask.mean() > 0.5
    exposure = scene.render.exposure
    a = to_srgb8(raster, exposure).astype(int)
    b = to_srgb8(traced, exposure).astype(int)
    assert np.abs(a - b)[mask].max() <= 1
    assert np.abs(raster - traced)[mask].max() <= 2e-3 * max(1.0, float(raster.max()))


def test_sphere_under_directional_light_matches_closed_form_phong():
    """Each sphere pixel equals Ia ka Od + Ip [kd Od N.L + ks (R.V)^n] at the analytic hit."""
    mat = Material(ka=0.2, kd=0.6, ks=0.3, n=20.0, Od=(0.9, 0.5, 0.2), Os=(1.0, 1.0, 1.0))
    light = Light(kind="directional", direction=(-1.0, -1.0, -1.0), Ip=(1.0, 0.9, 0.8))
    sphere = Object(shape="sphere", material="m", radius=1.0, subdivisions=5)
    scene = _scene([sphere], {"m": mat}, [light], Ia=(0.3, 0.3, 0.3))
    size = (40, 40)
    image = render_raytraced(scene, size, depth=0, spp=1)
    o, d = primary_rays(scene.camera, *size)
    # Analytic ray-sphere intersection |o + t d| = 1
    b = np.sum(o * d, axis=-1)
    disc = b * b - (np.sum(o * o, axis=-1) - 1.0)
    inside = disc > 0.05  # keep away from the silhouette (tessellated there)
    t = -b - np.sqrt(np.maximum(disc, 0.0))
    p = o + t[..., None] * d
    n = p / np.linalg.norm(p, axis=-1, keepdims=True)
    to_light = np.array([1.0, 1.0, 1.0]) / math.sqrt(3.0)
    ndl = np.maximum(n @ to_light, 0.0)
    r = 2.0 * n * ndl[..., None] - to_light
    rdv = np.maximum(np.sum(r * -d, axis=-1), 0.0)
    spec = np.where(ndl > 0, rdv ** 20.0, 0.0)
    od, ip = np.array(mat.Od), np.array(light.Ip)
    expected = 0.3 * 0.2 * od + ip * (0.6 * od * ndl[..., None] + 0.3 * spec[..., None])
    assert inside.sum() > 300
    np.testing.assert_allclose(image[inside], expected[inside], atol=0.02)


# ------------------------------------------------------------------ recursion


def _mirrors(kr: float, emission: float):
    """Two parallel mirror quads facing each other at z = +-1, both emitting Le."""
    mat = Material(ka=0.0, kd=0.0, ks=0.0, kr=kr, emission=(emission,) * 3)
    near = Object(shape="quad", material="m",
                  vertices=[[-5, -5, 1], [5, -5, 1], [5, 5, 1], [-5, 5, 1]])
    far = Object(shape="quad", material="m",
                 vertices=[[-5, -5, -1], [-5, 5, -1], [5, 5, -1], [5, -5, -1]])
    scene = _scene([near, far], {"m": mat}, [Light(Ip=(0.0, 0.0, 0.0))])
    scene.raytrace.min_weight = 0.0
    return scene


@pytest.mark.parametrize("k", [1, 3, 7])
def test_parallel_mirrors_weight_is_kr_to_the_k(k):
    """Between parallel mirrors, the ray after k bounces carries kr^k; radiance is sum kr^j Le."""
    kr = 0.6
    scene = _mirrors(kr, emission=1.0)
    ctx = TraceContext(scene)
    o = np.array([[0.0, 0.0, 0.0]])
    d = np.array([[0.0, 0.0, -1.0]])
    radiance = trace_batch(ctx, o, d, depth=k, fresnel=False, min_weight=0.0)
    np.testing.assert_allclose(radiance[0], sum(kr ** j for j in range(k + 1)), rtol=1e-9)
    # The ray tree of the same ray: a chain of reflected rays with weights kr^j
    chain = [ctx_node for _, ctx_node in _tree_from(ctx, o[0], d[0], k).flatten()
             if ctx_node.kind != "shadow"]
    assert len(chain) == k + 1
    for j, node in enumerate(chain):
        np.testing.assert_allclose(node.weight, kr ** j, rtol=1e-12)
        assert node.kind == ("primary" if j == 0 else "reflected")


def _tree_from(ctx, origin, direction, depth):
    from shadelab.raytrace.tree import _trace

    return _trace(ctx, "primary", origin, direction, np.ones(3), 0, depth, False)


def test_min_weight_stops_recursion_early_and_reports_depth():
    scene = _mirrors(0.5, emission=1.0)
    scene.raytrace.min_weight = 0.1  # 0.5^4 = 0.0625 < 0.1: three bounces only
    ctx = TraceContext(scene)
    from shadelab.raytrace.whitted import WavefrontStats

    stats = WavefrontStats()
    out = trace_batch(ctx, np.zeros((1, 3)), np.array([[0.0, 0.0, -1.0]]), 10, False, stats)
    assert stats.depth_reached == 3
    np.testing.assert_allclose(out[0], 1 + 0.5 + 0.25 + 0.125)


def test_glass_slab_displaces_the_ray_as_snell_predicts():
    """A ray through a slab of thickness h leaves parallel, shifted h sin(i - t) / cos t."""
    ior, h, theta = 1.5, 0.5, math.radians(40.0)
    glass = Material(ka=0.0, kd=0.0, ks=0.0, kr=0.0, kt=1.0, ior=ior)
    slab = Object(shape="box", material="g", extents=(20.0, h, 20.0))
    scene = _scene([slab], {"g": glass}, [Light(Ip=(0.0, 0.0, 0.0))])
    scene.raytrace.offset = 1e-6  # origins move off the surface by 3e-5: below the tolerance
    ctx = TraceContext(scene)
    d = np.array([math.sin(theta), -math.cos(theta), 0.0])
    o = np.array([0.0, 2.0, 0.0]) - 3.0 * d
    tree = _tree_from(ctx, o, d, 4)
    rays = [n for _, n in tree.flatten() if n.kind != "shadow"]
    kinds = [n.kind for n in rays]
    assert kinds[:3] == ["primary", "refracted", "refracted"]
    inside, out = rays[1], rays[2]
    theta_t = math.asin(math.sin(theta) / ior)
    np.testing.assert_allclose(math.acos(-inside.direction[1]), theta_t, atol=1e-9)
    np.testing.assert_allclose(out.direction, d, atol=1e-9)
    # Perpendicular distance between the incoming line and the outgoing line
    delta = out.origin - o
    shift = np.linalg.norm(delta - np.dot(delta, d) * d)
    expected = h * math.sin(theta - theta_t) / math.cos(theta_t)
    assert shift == pytest.approx(expected, abs=1e-3 * h)


def test_total_internal_reflection_past_the_critical_angle():
    ior = 1.5
    critical = math.asin(1.0 / ior)
    n = np.array([[0.0, 0.0, 1.0]] * 2)
    angles = [critical - 0.01, critical + 0.01]
    d = np.array([[math.sin(a), 0.0, -math.cos(a)] for a in angles])
    refl, refr, tir, f = reflect_refract(d, n, np.array([False, False]), np.array([ior, ior]))
    assert list(tir) == [False, True]
    assert f[1] == 1.0 and f[0] < 1.0
    np.testing.assert_allclose(refl[1], [d[1, 0], 0.0, -d[1, 2]], atol=1e-12)
    # Below the critical angle the refracted ray leaves at nearly 90 degrees
    assert abs(refr[0, 2]) < 0.2
    # End to end: without Fresnel, kt goes to reflection under TIR
    glass = Material(kt=1.0, kr=0.0, ks=0.0, ior=ior)
    scene = _scene([Object(shape="sphere", material="g")], {"g": glass}, [Light()])
    ctx = TraceContext(scene)
    from shadelab.raytrace.surface import Surface

    surf = Surface(np.zeros((2, 3)), n, n, np.array([False, False]), np.zeros(2, np.int64))
    _, refl_w, _, refr_w = ctx.secondary(surf, d, fresnel=False)
    np.testing.assert_allclose(refl_w[:, 0], [0.0, 1.0])
    np.testing.assert_allclose(refr_w[:, 0], [1.0, 0.0])


def test_fresnel_at_normal_incidence_and_energy_split():
    ior = 1.5
    d = np.array([[0.0, 0.0, -1.0]])
    n = np.array([[0.0, 0.0, 1.0]])
    _, refr, tir, f = reflect_refract(d, n, np.array([True]), np.array([ior]))
    assert f[0] == pytest.approx(((ior - 1) / (ior + 1)) ** 2, rel=1e-12)
    np.testing.assert_allclose(refr[0], [0.0, 0.0, -1.0], atol=1e-12)
    glass = Material(kt=0.8, kr=0.1, ks=0.0, ior=ior)
    scene = _scene([Object(shape="sphere", material="g")], {"g": glass}, [Light()])
    from shadelab.raytrace.surface import Surface

    surf = Surface(np.zeros((1, 3)), n, n, np.array([True]), np.zeros(1, np.int64))
    _, refl_w, _, refr_w = TraceContext(scene).secondary(surf, d, fresnel=True)
    assert refl_w[0, 0] == pytest.approx(0.1 + 0.8 * 0.04)
    assert refr_w[0, 0] == pytest.approx(0.8 * 0.96)


def test_ray_tree_contributions_sum_to_the_pixel():
    scene = load_preset("cornell-spheres")
    size = (32, 32)
    image = render_raytraced(scene, size, depth=4, spp=1)
    for x, y in [(11, 22), (20, 22), (16, 5), (3, 3)]:
        tree = trace_pixel_tree(scene, size, x, y, depth=4)
        np.testing.assert_allclose(tree.total(), image[y, x], rtol=1e-4, atol=1e-5)
        depths = [d for d, _ in tree.flatten()]
        assert depths[0] == 0
        assert {n.kind for _, n in tree.flatten()} <= {"primary", "shadow", "reflected",
                                                       "refracted"}
    # The glass sphere's pixel has refracted children and a shadow ray to the light
    tree = trace_pixel_tree(scene, size, 20, 22, depth=4)
    kinds = [n.kind for _, n in tree.flatten()]
    assert "refracted" in kinds and "shadow" in kinds


def test_ray_tree_shadow_ray_names_its_blocker():
    """A floor pixel in the mirror sphere's shadow: S = 0, the blocker is the sphere."""
    scene = load_preset("cornell-spheres")
    mirror = [o.name for o in scene.objects].index("mirror_sphere")
    floor = [o.name for o in scene.objects].index("floor")
    tree = trace_pixel_tree(scene, (32, 32), 12, 27, depth=2)
    assert tree.kind == "primary" and tree.object == floor
    shadow = [n for n in tree.children if n.kind == "shadow"]
    assert len(shadow) == 1 and shadow[0].shadow == 0.0 and shadow[0].object == mirror
    centre = np.array([370.0, 100.0, 350.0])
    assert abs(np.linalg.norm(shadow[0].end - centre) - 100.0) < 1.0  # on the sphere
    np.testing.assert_allclose(tree.local, 0.0, atol=1e-12)  # kd Od, but no light: black


# ------------------------------------------------------------------ shadows


def _tilted_plane(offset: float) -> Scene:
    mat = Material(ka=0.0, kd=0.8, ks=0.0)
    plane = Object(shape="plane", material="m", size=4.0, rotate=(17.0, 0.0, 11.0),
                   segments=4)
    light = Light(kind="point", position=(0.3, 4.0, 2.0), Ip=(1.0, 1.0, 1.0))
    scene = _scene([plane], {"m": mat}, [light], eye=(0.2, 3.0, 3.0), target=(0, 0, 0))
    scene.raytrace.offset = offset
    return scene


def test_no_shadow_acne_with_the_default_offset():
    scene = _tilted_plane(offset=1e-3)
    size = (48, 48)
    lit = render_raytraced(scene, size, depth=0, shadows=False)
    shadowed = render_raytraced(scene, size, depth=0, shadows=True)
    covered = lit.max(axis=2) > 0
    assert covered.mean() > 0.3
    np.testing.assert_allclose(shadowed, lit, atol=1e-12)


def test_shadow_acne_appears_with_zero_offset():
    """Failure gallery: shadow rays from the surface itself hit it (speckled darkness)."""
    scene = _tilted_plane(offset=0.0)
    size = (48, 48)
    lit = render_raytraced(scene, size, depth=0, shadows=False)
    shadowed = render_raytraced(scene, size, depth=0, shadows=True)
    covered = lit.max(axis=2) > 0
    acne = covered & (shadowed.max(axis=2) < 0.5 * lit.max(axis=2))
    assert acne.sum() / covered.sum() > 0.05


# ------------------------------------------------------------------ acceleration


def test_embree_and_bvh_give_the_same_hits(np_rng):
    from shadelab.raytrace.accel import BvhAccel, EmbreeAccel

    scene = load_preset("cornell-spheres")
    geometry = scene_geometry(scene)
    embree, bvh = EmbreeAccel(geometry), BvhAccel(geometry)
    n = 4000
    o = np_rng.uniform([10, 10, 10], [540, 540, 550], size=(n, 3))
    d = np_rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    a, b = embree.intersect(o, d), bvh.intersect(o, d)
    assert a.hit.mean() > 0.5  # the room is open toward the camera only
    assert (a.hit == b.hit).mean() > 0.998
    same = a.tri == b.tri
    assert same.mean() > 0.998  # ties on shared edges may pick either triangle
    both = a.hit & b.hit
    np.testing.assert_allclose(a.t[both], b.t[both], rtol=1e-4, atol=1e-3)
    np.testing.assert_allclose(a.u[same], b.u[same], atol=1e-3)
    tmax = np.full(n, 200.0)
    assert (embree.occluded(o, d, tmax) == bvh.occluded(o, d, tmax)).mean() > 0.998


def test_bvh_backend_renders_the_same_image():
    scene = load_preset("cornell-spheres")
    size = (24, 24)
    a = render_raytraced(scene, size, depth=3, backend="embree")
    b = render_raytraced(scene, size, depth=3, backend="bvh")
    assert np.mean(np.abs(a - b) > 1e-3) < 0.01


# ------------------------------------------------------------------ progressive, pool


def test_progress_fractions_and_cancel():
    from shadelab.raytrace import whitted

    scene = load_preset("cornell-spheres")
    gen = whitted.iter_raytrace(scene, (64, 1024), depth=1, spp=2)  # 2 tiles per pass
    steps = [next(gen), next(gen)]
    gen.close()
    assert [s.fraction for s in steps] == [0.25, 0.5]
    assert steps[0].image[:512].max() > 0 and steps[0].image[512:].max() == 0
    assert steps[1].stats["primary_rays"] == 64 * 1024


def test_two_worker_processes_give_the_same_image():
    scene = load_preset("cornell-spheres")
    size = (48, 700)  # 2 tiles
    serial = render_raytraced(scene, size, depth=2, spp=2)
    pooled = render_raytraced(scene, size, depth=2, spp=2, workers=2)
    np.testing.assert_array_equal(serial, pooled)


# ------------------------------------------------------------------ command line


def test_cli_writes_png_and_npy(tmp_path, capsys):
    out, npy = tmp_path / "a.png", tmp_path / "a.npy"
    code = main(["raytrace", "cornell-spheres", "-o", str(out), "--size", "24x20", "--depth",
                 "2", "--spp", "2", "--fresnel", "--npy", str(npy)])
    assert code == 0
    image = np.load(npy)
    assert image.shape == (20, 24, 3) and image.dtype == np.float32
    assert np.isfinite(image).all() and image.max() > 0
    assert out.is_file()
    assert "depth reached 2" in capsys.readouterr().out


@pytest.mark.parametrize("argv", [
    ["--depth", "-1"], ["--depth", "65"], ["--spp", "0"], ["--size", "0x10"],
    ["--set", "lights.0.enabled=false"], ["--depth", "x"], ["--workers", "0"],
])
def test_cli_bad_input_exits_2_with_one_line(tmp_path, capsys, argv):
    code = main(["raytrace", "cornell-spheres", "-o", str(tmp_path / "a.png"), *argv])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1 and err.startswith("shadelab: error:")
    assert not (tmp_path / "a.png").exists()


EMPTY = """schema_version = 1
[camera]
eye = [0.0, 0.0, 5.0]
target = [0.0, 0.0, 0.0]
[[lights]]
kind = "point"
position = [0.0, 5.0, 0.0]
"""


def test_cli_empty_scene_exits_2(tmp_path, capsys):
    preset = tmp_path / "empty.toml"
    preset.write_text(EMPTY)
    code = main(["raytrace", str(preset), "-o", str(tmp_path / "a.png")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "objects" in err


def test_cli_nothing_visible_writes_the_background_and_a_note(tmp_path, capsys):
    """Objects exist but none is in view: exit 0, the background image, one note on stderr."""
    preset = tmp_path / "behind.toml"
    preset.write_text(EMPTY + """[render]
background = [0.25, 0.5, 0.75]
[materials.default]
kd = 0.5
[[objects]]
shape = "sphere"
translate = [0.0, 0.0, 20.0]
""")
    npy = tmp_path / "a.npy"
    code = main(["raytrace", str(preset), "-o", str(tmp_path / "a.png"), "--size", "8x6",
                 "--npy", str(npy)])
    err = capsys.readouterr().err
    assert code == 0
    assert "note: no object is visible" in err
    np.testing.assert_allclose(np.load(npy), np.broadcast_to([0.25, 0.5, 0.75], (6, 8, 3)))
