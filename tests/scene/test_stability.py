"""Stability, property-based: no NaN, Inf or negative pixel, no crash, for any coefficients,
light placement or mesh the scene model accepts (extreme ones included: n = 0 and 1e4,
c1 = c2 = c3 = 0, Ip = 0, kd + ks > 1, a light on the surface, zero normals, degenerate
triangles).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from shadelab.geometry.normals import corner_normals, face_normals
from shadelab.scene.model import NORMALS_MODES, Camera, Light, Material, Object, Scene
from shadelab.shading.reference import shade

FAST = settings(max_examples=20, deadline=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture,
                                       HealthCheck.too_slow])

unit = st.floats(0.0, 1.0)
coord = st.floats(-5.0, 5.0)
rgb = st.tuples(st.floats(0.0, 10.0), st.floats(0.0, 10.0), st.floats(0.0, 10.0))
vec3 = st.tuples(coord, coord, coord)
shininess = st.sampled_from([0.0, 1e-3, 1.0, 10.0, 100.0, 1e4]) | st.floats(0.0, 1e4)


@st.composite
def materials(draw) -> Material:
    """Any coefficients the schema allows (kd + ks > 1 included)."""
    return Material(ka=draw(unit), kd=draw(unit), ks=draw(unit), n=draw(shininess),
                    Od=draw(st.tuples(unit, unit, unit)), Os=draw(st.tuples(unit, unit, unit)))


@st.composite
def lights(draw) -> Light:
    """Point, directional or spot lights, every attenuation mode, c's possibly all zero."""
    kind = draw(st.sampled_from(["point", "directional", "spot"]))
    direction = draw(vec3.filter(lambda v: sum(c * c for c in v) > 1e-6))
    return Light(kind=kind, position=draw(vec3), direction=direction, Ip=draw(rgb),
                 attenuation=draw(st.sampled_from(["none", "inverse_square", "lecture"])),
                 c1=draw(st.floats(0.0, 2.0)), c2=draw(st.floats(0.0, 2.0)),
                 c3=draw(st.floats(0.0, 2.0)), cone_angle=draw(st.floats(0.0, 90.0)),
                 spot_exponent=draw(st.floats(0.0, 1000.0)))


def _assert_clean(image: np.ndarray, what: str) -> None:
    assert np.all(np.isfinite(image)), f"{what}: NaN or Inf"
    assert image.min() >= 0.0, f"{what}: negative value {image.min()}"


# ---------------------------------------------------------------- numpy reference

@FAST
@given(material=materials(), light_list=st.lists(lights(), min_size=0, max_size=3),
       Ia=rgb, specular=st.sampled_from(["phong", "blinn"]), seed=st.integers(0, 2**31))
def test01_reference_shade_is_finite_and_non_negative(material, light_list, Ia, specular, seed):
    rng = np.random.default_rng(seed)
    points = rng.uniform(-5, 5, (64, 3))
    normals = rng.normal(size=(64, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    normals[:4] = 0.0                                    # zero-length normals
    eye = points[5].copy()                               # the eye on a surface point
    for i, light in enumerate(light_list):
        points[6 + i] = light.position                   # a light on a surface point
    image = shade(points, normals, eye, material, light_list, Ia, specular)
    _assert_clean(image, "reference.shade")


@FAST
@given(material=materials(), light=lights())
def test02_reference_black_light_adds_nothing(material, light):
    """Ip = 0 contributes exactly 0 (no NaN from 0 * inf at a coincident light)."""
    light.Ip = (0.0, 0.0, 0.0)
    p = np.array([[0.0, 0.0, 0.0], list(light.position)])
    n = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]])
    out = shade(p, n, np.array([0.0, 0.0, 3.0]), material, [light], (0.0, 0.0, 0.0))
    assert np.array_equal(out, np.zeros_like(out))


# ---------------------------------------------------------------- meshes and normals

@st.composite
def triangle_soups(draw):
    """Few vertices on a coarse grid, so duplicates, collinear and zero-area faces are common."""
    nv = draw(st.integers(3, 8))
    grid = st.integers(-2, 2).map(float)
    vertices = np.array(draw(st.lists(st.tuples(grid, grid, grid), min_size=nv, max_size=nv)))
    index = st.integers(0, nv - 1)
    faces = np.array(draw(st.lists(st.tuples(index, index, index), min_size=1, max_size=10)))
    return vertices, faces


@FAST
@given(soup=triangle_soups(), mode=st.sampled_from(NORMALS_MODES),
       crease=st.floats(0.0, 180.0))
def test03_normals_of_degenerate_meshes_are_unit_or_zero(soup, mode, crease):
    vertices, faces = soup
    fn = face_normals(vertices, faces)
    cn = corner_normals(vertices, faces, mode, crease)
    assert np.all(np.isfinite(fn)) and np.all(np.isfinite(cn))
    for lengths in (np.linalg.norm(fn, axis=-1), np.linalg.norm(cn, axis=-1)):
        assert np.all((np.abs(lengths - 1.0) < 1e-6) | (lengths < 1e-9))


# ---------------------------------------------------------------- raster (GL)

def _tiny_scene(material: Material, light_list: list[Light], Ia, quad=None) -> Scene:
    scene = Scene(Ia=Ia)
    scene.camera = Camera(eye=(0.0, 1.0, 4.0), target=(0.0, 0.0, 0.0), fov_y=50.0, near=0.05)
    scene.lights = light_list
    scene.materials = {"m": material}
    scene.objects = [Object(shape="sphere", material="m", subdivisions=1),
                     Object(shape="plane", material="m", size=6.0, translate=(0.0, -1.0, 0.0))]
    if quad is not None:
        scene.objects.append(Object(shape="quad", material="m", vertices=quad, segments=2))
    return scene


@pytest.mark.gl
@settings(max_examples=12, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(material=materials(), light_list=st.lists(lights(), min_size=1, max_size=3), Ia=rgb,
       shading=st.sampled_from(["flat", "gouraud", "phong"]),
       specular=st.sampled_from(["phong", "blinn"]),
       quad=st.lists(st.tuples(*[st.integers(-1, 1).map(float)] * 3), min_size=4, max_size=4),
       passes=st.sampled_from([("none", "zfail", "zbuffer"), ("volumes", "zfail", "zbuffer"),
                               ("volumes", "zpass", "zbuffer"), ("none", "zfail", "painter")]),
       kt=st.sampled_from([0.0, 0.5, 1.0]))
def test04_raster_is_finite_and_non_negative(gl_ctx, material, light_list, Ia, shading,
                                              specular, quad, passes, kt):
    from shadelab.raster.offscreen import render_image

    scene = _tiny_scene(material, light_list, Ia, quad)    # the quad is often degenerate
    scene.render.shadows, scene.render.shadow_method, scene.render.visibility = passes
    scene.materials["glass"] = Material(kt=kt, ka=0.1, kd=0.5, Od=(0.2, 0.6, 0.9))
    scene.objects.append(Object(shape="box", material="glass", extents=(0.5, 0.5, 0.5),
                                translate=(0.8, 0.0, 1.0)))   # transparent when kt > 0
    image = render_image(scene, (16, 12), shading, specular)
    _assert_clean(image, f"raster {shading}")


# ---------------------------------------------------------------- ray tracer, radiosity

@st.composite
def trace_materials(draw) -> Material:
    """Local coefficients plus mirror, glass and emission (what the CPU tracers read)."""
    m = draw(materials())
    m.kr = draw(st.sampled_from([-1.0, 0.0, 0.5, 1.0]))
    m.kt = draw(st.sampled_from([0.0, 0.5, 1.0]))
    m.ior = draw(st.sampled_from([1.0, 1.33, 1.5, 2.4, 5.0]))
    m.emission = draw(st.sampled_from([(0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (5.0, 2.0, 0.0)]))
    return m


def _trace_scene(ball: Material, floor: Material, light_list: list[Light]) -> Scene:
    scene = _tiny_scene(floor, light_list, (0.1, 0.1, 0.1))
    scene.materials["ball"] = ball
    scene.objects[0].material = "ball"
    return scene


@settings(max_examples=15, deadline=None)
@given(ball=trace_materials(), floor=trace_materials(),
       light_list=st.lists(lights(), min_size=1, max_size=2),
       depth=st.integers(0, 6), fresnel=st.booleans())
def test05_raytracer_is_finite_and_non_negative(ball, floor, light_list, depth, fresnel):
    from shadelab.raytrace.whitted import render_raytraced

    image = render_raytraced(_trace_scene(ball, floor, light_list), (12, 9), depth, 1,
                             fresnel)
    _assert_clean(np.asarray(image, dtype=np.float64), "raytrace")


@settings(max_examples=10, deadline=None)
@given(ball=trace_materials(), floor=trace_materials(),
       light_list=st.lists(lights(), min_size=1, max_size=2), seed=st.integers(0, 1000))
def test06_pathtracer_is_finite_and_non_negative(ball, floor, light_list, seed):
    from shadelab.raytrace.pathtrace import iter_pathtrace

    floor.emission = (1.0, 1.0, 1.0)                     # the path tracer needs an emitter
    steps = list(iter_pathtrace(_trace_scene(ball, floor, light_list), (10, 8), 2, seed))
    _assert_clean(np.asarray(steps[-1].image, dtype=np.float64), "pathtrace")


def _room(rho: list[float], emitter: int, radiance: float) -> Scene:
    """A closed unit box (six quads, inward normals), one wall emitting."""
    faces = [
        [[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1]],  # floor, normal +y
        [[0, 1, 0], [0, 1, 1], [1, 1, 1], [1, 1, 0]],  # ceiling, -y
        [[0, 0, 0], [0, 0, 1], [0, 1, 1], [0, 1, 0]],  # x = 0, +x
        [[1, 0, 0], [1, 1, 0], [1, 1, 1], [1, 0, 1]],  # x = 1, -x
        [[0, 0, 0], [0, 1, 0], [1, 1, 0], [1, 0, 0]],  # z = 0, +z
        [[0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],  # z = 1, -z
    ]
    scene = Scene(Ia=(0.0, 0.0, 0.0))
    scene.camera = Camera(eye=(0.5, 0.5, 0.05), target=(0.5, 0.5, 1.0), fov_y=80.0, near=0.01)
    for i, (poly, r) in enumerate(zip(faces, rho, strict=True)):
        emission = (radiance,) * 3 if i == emitter else (0.0, 0.0, 0.0)
        scene.materials[f"m{i}"] = Material(ka=0.0, kd=1.0, ks=0.0, Od=(r, r, r),
                                            emission=emission)
        scene.objects.append(Object(shape="quad", material=f"m{i}", normals="flat",
                                    vertices=[[float(c) for c in p] for p in poly]))
    return scene


@settings(max_examples=15, deadline=None)
@given(rho=st.lists(st.floats(0.0, 0.95), min_size=6, max_size=6),
       emitter=st.integers(0, 5), radiance=st.floats(0.01, 100.0),
       solver=st.sampled_from(["direct", "jacobi", "gauss-seidel", "progressive"]),
       count=st.integers(6, 60))
def test07_radiosity_creates_no_energy(rho, emitter, radiance, solver, count):
    """B >= E, B <= E_max / (1 - rho_max), and absorbed power <= emitted power (rho < 1)."""
    from shadelab.radiosity.formfactors import FormFactors
    from shadelab.radiosity.patches import uniform_patches
    from shadelab.radiosity.solvers import solve

    patches = uniform_patches(_room(rho, emitter, radiance), count)
    F = FormFactors(patches, "raycast").matrix()
    B, _ = solve(solver, F, patches.rho, patches.E, patches.areas, iterations=500,
                 tolerance=1e-7)
    E, A, r = patches.E, patches.areas, patches.rho
    _assert_clean(B, f"radiosity {solver}")
    assert np.all(B >= E * (1 - 1e-9))
    bound = E.max() / (1.0 - r.max())
    assert B.max() <= bound * (1 + 2e-3)
    incident = F @ B                                      # H_i per unit area
    absorbed = ((1.0 - r) * incident * A[:, None]).sum()
    emitted = (E * A[:, None]).sum()
    assert absorbed <= emitted * (1 + 2e-3)
