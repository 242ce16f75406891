"""The reference path tracer against closed forms (furnace, point-to-square form factor)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shadelab.cli import main
from shadelab.raytrace.pathtrace import iter_pathtrace, render_pathtraced
from shadelab.scene.camera import primary_rays
from shadelab.scene.model import Camera, Light, Material, Object, Scene
from shadelab.scene.preset import load_preset
from shadelab.shading.reference import shade


def _furnace(rho: tuple, le: tuple) -> Scene:
    """A closed box, every face emitting Le and reflecting rho; the camera inside."""
    mat = Material(ka=0.0, kd=1.0, Od=rho, ks=0.0, emission=le)
    return Scene(Ia=(0.0, 0.0, 0.0), lights=[], materials={"m": mat},
                 camera=Camera(eye=(0.1, 0.2, 0.3), target=(1.0, 0.5, 0.2), fov_y=90.0),
                 objects=[Object(shape="box", material="m", extents=(2.0, 2.0, 2.0))])


@pytest.mark.parametrize("sampler", ["sobol", "independent"])
@pytest.mark.parametrize("rho, spread", [((0.5, 0.45, 0.4), 0.25), ((0.8, 0.7, 0.3), 0.4)])
def test_furnace_converges_to_le_over_one_minus_rho(rho, spread, sampler):
    """L = Le / (1 - rho) everywhere: image mean within 2 %, 99 % of pixels within
    ``spread`` (32 samples per pixel; longer paths at rho 0.8 are noisier), with either
    sampler."""
    le = np.array([1.0, 0.5, 2.0])
    image = render_pathtraced(_furnace(rho, tuple(le)), (24, 24), 32, seed=1, sampler=sampler)
    expected = le / (1.0 - np.array(rho))
    ratio = image.reshape(-1, 3) / expected
    np.testing.assert_allclose(ratio.mean(axis=0), 1.0, atol=0.02)
    assert np.percentile(np.abs(ratio - 1.0), 99) < spread


def test_numpy_reference_path_agrees_on_the_furnace():
    """The numpy implementation (the readable one) of the same estimator: within 2 %."""
    rho, le = np.array([0.6, 0.5, 0.4]), np.array([1.0, 1.0, 1.0])
    scene = _furnace(tuple(rho), tuple(le))
    last = list(iter_pathtrace(scene, (16, 16), 16, seed=4, local="numpy"))[-1]
    ratio = last.image.reshape(-1, 3) * (1.0 - rho) / le
    np.testing.assert_allclose(ratio.mean(axis=0), 1.0, atol=0.02)


def _corner_factor(x: float, y: float) -> float:
    """Point to a parallel rectangle x by y at unit height, the point under a corner.

    F = 1/(2 pi) [X/sqrt(1+X^2) atan(Y/sqrt(1+X^2)) + Y/sqrt(1+Y^2) atan(X/sqrt(1+Y^2))]
    """
    a, b = math.sqrt(1 + x * x), math.sqrt(1 + y * y)
    return (x / a * math.atan(y / a) + y / b * math.atan(x / b)) / (2.0 * math.pi)


def _signed_corner(x: float, y: float) -> float:
    """The corner factor of the rectangle [0, x] x [0, y], signed (inclusion-exclusion)."""
    return math.copysign(1.0, x) * math.copysign(1.0, y) * _corner_factor(abs(x), abs(y))


def _square_emitter_scene(size: tuple[int, int]) -> tuple[Scene, np.ndarray]:
    """A floor under a square emitter and its radiance at the pixel centres:
    L = rho Le F(point -> square), F in closed form."""
    h, half = 1.0, 0.5
    le, rho = 3.0, 0.6
    floor = Object(shape="quad", material="floor",
                   vertices=[[-3, 0, 3], [3, 0, 3], [3, 0, -3], [-3, 0, -3]])
    lamp = Object(shape="quad", material="lamp",
                  vertices=[[-half, h, -half], [half, h, -half], [half, h, half], [-half, h, half]])
    scene = Scene(Ia=(0.0, 0.0, 0.0), lights=[],
                  materials={"floor": Material(ka=0, kd=1.0, Od=(rho,) * 3, ks=0.0),
                             "lamp": Material(ka=0, kd=0.0, ks=0.0, emission=(le,) * 3)},
                  camera=Camera(eye=(0.0, 0.6, 2.0), target=(0.0, 0.0, 0.0), fov_y=8.0),
                  objects=[floor, lamp])
    o, d = primary_rays(scene.camera, *size)
    t = -o[..., 1] / d[..., 1]
    p = o + t[..., None] * d
    expected = np.zeros(size[::-1])
    for j in range(size[1]):
        for i in range(size[0]):
            x, z = p[j, i, 0], p[j, i, 2]
            f = sum(sx * sz * _signed_corner((cx - x) / h, (cz - z) / h)
                    for cx, sx in ((half, 1), (-half, -1)) for cz, sz in ((half, 1), (-half, -1)))
            expected[j, i] = rho * le * f
    return scene, expected


def test_direct_light_from_a_square_emitter_matches_the_form_factor():
    """A floor under a square emitter: L = rho Le F(point -> square), F in closed form."""
    size = (8, 8)
    scene, expected = _square_emitter_scene(size)
    image = render_pathtraced(scene, size, 256, seed=2)
    np.testing.assert_allclose(image[..., 0].mean(), expected.mean(), rtol=0.02)
    np.testing.assert_allclose(image[..., 0], expected, rtol=0.15)


def test_sobol_samples_reach_the_form_factor_with_a_quarter_of_the_samples():
    """The same floor at 64 spp with the (default) Sobol' sampler: RMS relative error over
    the pixels below 3 %, every pixel within 10 % (independent samples measured ~5 % RMS,
    12-22 % worst pixel; Sobol' ~1.7 % RMS, 4-5.5 %, part of it the pixel footprint's
    variation about the centre's closed form)."""
    size = (8, 8)
    scene, expected = _square_emitter_scene(size)
    rel = render_pathtraced(scene, size, 64, seed=2)[..., 0] / expected - 1.0
    assert np.sqrt(np.mean(rel ** 2)) < 0.03
    assert np.abs(rel).max() < 0.10


def test_emitter_seen_by_the_camera_is_its_radiance():
    scene = load_preset("cornell")
    image = render_pathtraced(scene, (32, 32), 2)
    # Pixel (15, 4) looks at the ceiling light (kd 0: nothing but Le)
    np.testing.assert_allclose(image[4, 15], [20.71, 10.85, 2.77], rtol=1e-5)


def test_progress_is_monotone_and_cancel_stops_promptly():
    scene = load_preset("cornell")
    gen = iter_pathtrace(scene, (16, 16), 3, seed=0)
    fractions = []
    for step in gen:
        fractions.append(step.fraction)
        assert step.image.shape == (16, 16, 3) and step.image.dtype == np.float32
        if len(fractions) == 2:
            gen.close()
            break
    assert fractions == sorted(fractions) and fractions[-1] < 1.0
    last = list(iter_pathtrace(scene, (16, 16), 2))[-1]
    assert last.fraction == 1.0 and last.stats["samples"] == 16 * 16 * 2
    assert last.stats["samples_per_s"] > 0


def test_same_seed_same_image_other_seed_differs():
    scene = load_preset("cornell")
    a = render_pathtraced(scene, (12, 12), 2, seed=5)
    b = render_pathtraced(scene, (12, 12), 2, seed=5)
    c = render_pathtraced(scene, (12, 12), 2, seed=6)
    np.testing.assert_array_equal(a, b)
    assert np.abs(a - c).max() > 0


def test_two_worker_processes_give_the_same_image():
    scene = load_preset("cornell")
    size = (16, 2048)  # 2 tiles per pass
    serial = render_pathtraced(scene, size, 2, seed=3)
    pooled = render_pathtraced(scene, size, 2, seed=3, workers=2)
    np.testing.assert_array_equal(serial, pooled)


def test_cli_pathtrace_writes_radiance(tmp_path):
    npy = tmp_path / "p.npy"
    code = main(["pathtrace", "cornell", "-o", str(tmp_path / "p.png"), "--size", "16x12",
                 "--spp", "2", "--npy", str(npy)])
    assert code == 0
    image = np.load(npy)
    assert image.shape == (12, 16, 3) and np.isfinite(image).all()


@pytest.mark.parametrize("argv", [
    ["--spp", "0"], ["--size", "0"], ["--set", "materials.light.emission=0,0,0"],
])
def test_cli_pathtrace_bad_input_exits_2(tmp_path, capsys, argv):
    code = main(["pathtrace", "cornell", "-o", str(tmp_path / "p.png"), *argv])
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and err.startswith("shadelab: error:")


# ---------------------------------------------------------------- the lecture's lights

_LIGHTS = {
    "point": Light(kind="point", position=(0.3, 1.2, 0.8), Ip=(0.9, 0.7, 0.5),
                   attenuation="lecture", c1=0.5, c2=0.3, c3=0.2),
    "spot": Light(kind="spot", position=(0.0, 1.5, 0.0), direction=(0.1, -1.0, 0.05),
                  Ip=(1.0, 1.0, 0.8), cone_angle=35.0, spot_exponent=4.0,
                  attenuation="inverse_square"),
    "directional": Light(kind="directional", direction=(-0.4, -1.0, -0.3), Ip=(0.6, 0.8, 1.0)),
}


@pytest.mark.parametrize("kind", sorted(_LIGHTS))
@pytest.mark.parametrize("specular", ["phong", "blinn"])
@pytest.mark.parametrize("local", ["numba", "numpy"])
def test_first_bounce_of_a_lecture_light_is_the_local_model(kind, specular, local):
    """One plane under a point, spot or directional light, nothing else to bounce off: each
    camera path's radiance is exactly the lecture's I = S f_att Ip [kd Od N.L + ks Os (R.V)^n]
    at its hit (ambient left to the paths), whatever the estimator's random numbers."""
    from shadelab.raytrace.pathtrace import PathTracer

    plane = Material(ka=0.3, kd=0.6, Od=(0.9, 0.5, 0.3), ks=0.4, n=20.0, Os=(1.0, 0.9, 0.8))
    light = _LIGHTS[kind]
    scene = Scene(Ia=(0.2, 0.2, 0.2), lights=[light], materials={"m": plane},
                  camera=Camera(eye=(0.4, 1.0, 2.5), target=(0.0, 0.0, 0.0), fov_y=50.0),
                  objects=[Object(shape="quad", material="m",
                                  vertices=[[-2, 0, 2], [2, 0, 2], [2, 0, -2], [-2, 0, -2]])])
    scene.render.specular = specular
    tracer = PathTracer(scene, local=local)
    o, d = primary_rays(scene.camera, 32, 24)
    o, d = o.reshape(-1, 3), d.reshape(-1, 3)
    got = tracer.radiance(o, d, np.random.default_rng(3))
    t = -o[:, 1] / d[:, 1]
    on_plane = (t > 0) & np.all(np.abs((o + t[:, None] * d)[:, [0, 2]]) < 2.0, axis=1)
    assert on_plane.mean() > 0.5
    points = o[on_plane] + t[on_plane, None] * d[on_plane]
    expected = shade(points, np.array([0.0, 1.0, 0.0]), scene.camera.eye, plane, [light],
                     (0.0, 0.0, 0.0), specular)
    np.testing.assert_allclose(got[on_plane], expected, rtol=1e-6, atol=1e-9)
    assert expected.max() > 0.05 and np.all(got[~on_plane] == 0.0)


def test_a_stand_in_light_is_left_to_the_surface_it_stands_for():
    """Cornell's point light stands in for the ceiling quad: the path tracer skips it (the
    image is the same with the light removed), and a scene lit only by stand-ins is refused."""
    scene = load_preset("cornell")
    assert [light.stand_in for light in scene.lights] == [True]
    with_light = render_pathtraced(scene, (12, 12), 2, seed=4)
    scene.lights = []
    np.testing.assert_array_equal(render_pathtraced(scene, (12, 12), 2, seed=4), with_light)
    from shadelab.errors import ShadeLabError
    from shadelab.raytrace.pathtrace import check_lit

    dark = load_preset("cornell")
    for material in dark.materials.values():
        material.emission = (0.0, 0.0, 0.0)
    with pytest.raises(ShadeLabError, match="stand_in"):
        check_lit(dark, "cornell")
    check_lit(load_preset("whitted"), "whitted")  # lit by its lights alone: accepted


@pytest.mark.parametrize("local", ["numba", "numpy"])
def test_textures_and_bumps_in_the_path_tracer_first_bounce(local):
    """surface-detail (checker floor, brick wall with a height map, a bumpy sphere) lit by its
    lecture lights, Ia = 0: each camera path's direct term equals Whitted's local model at
    depth 0, which matches the raster's texture lookups (tests/raytrace/
    test_raytrace_detail.py); the
    same scene without its textures differs."""
    from shadelab.raytrace.accel import Hits
    from shadelab.raytrace.pathtrace import PathTracer
    from shadelab.raytrace.surface import TraceContext

    scene = load_preset("surface-detail")
    scene.Ia = (0.0, 0.0, 0.0)
    o, d = primary_rays(scene.camera, 40, 30)
    o, d = o.reshape(-1, 3), d.reshape(-1, 3)
    tracer = PathTracer(scene, local=local)
    # only the first bounce: no other bounce may add light, so compare the delta-light term
    ctx = tracer.ctx
    hits = ctx.accel.intersect(o, d)
    keep = np.flatnonzero(hits.hit)
    surf = ctx.surface(o[keep], d[keep], Hits(hits.t[keep], hits.tri[keep], hits.u[keep],
                                               hits.v[keep]))
    mat = ctx.object_material[surf.obj]
    got = tracer._delta_lights(surf, d[keep], mat, tracer._detail(surf, mat))
    whitted = TraceContext(scene, local=local)
    wsurf = whitted.surface(o[keep], d[keep], Hits(hits.t[keep], hits.tri[keep],
                                                     hits.u[keep], hits.v[keep]))
    expected = whitted.local(wsurf, d[keep])
    emission = np.array([m.emission for m in whitted.materials])[mat]
    np.testing.assert_allclose(got, expected - emission, rtol=1e-6, atol=1e-9)
    untextured = ["materials.checker.texture=", "materials.bricks.texture=",
                  "materials.bricks.bump=", "materials.bumpy.bump="]
    plain = PathTracer(load_preset("surface-detail", untextured), local=local)
    psurf = plain.ctx.surface(o[keep], d[keep], Hits(hits.t[keep], hits.tri[keep],
                                                       hits.u[keep], hits.v[keep]))
    flat = plain._delta_lights(psurf, d[keep], mat, plain._detail(psurf, mat))
    assert np.abs(flat - got).max() > 0.05
