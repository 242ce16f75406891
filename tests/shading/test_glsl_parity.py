"""The GLSL include evaluates the same lighting equation as the numpy reference.

Seeded random points, normals, materials and lights (every light kind and attenuation mode,
both specular models) are shaded on the GPU into an N x 1 RGBA32F target and compared with
shadelab.shading.reference.shade: |error| <= 1e-4 relative (+1e-5 absolute).
"""

from __future__ import annotations

from pathlib import Path

import moderngl
import numpy as np
import pytest

from shadelab.gl.programs import register_includes, set_uniform, with_defines
from shadelab.raster.renderer import Renderer, write_light_uniforms
from shadelab.scene.model import Light, Material
from shadelab.shading.reference import normalize, shade

pytestmark = pytest.mark.gl
N_POINTS = 256
SHADERS = Path(__file__).resolve().parents[1] / "shaders"


def _random_light(rng: np.random.Generator, kind: str, attenuation: str) -> Light:
    return Light(kind=kind, position=tuple(rng.uniform(-3, 3, 3)),
                 direction=tuple(rng.normal(size=3)), Ip=tuple(rng.uniform(0, 2, 3)),
                 attenuation=attenuation, c1=float(rng.uniform(0, 1)),
                 c2=float(rng.uniform(0, 1)), c3=float(rng.uniform(0, 1)),
                 cone_angle=float(rng.uniform(10, 80)), spot_exponent=float(rng.uniform(0, 20)))


def _random_material(rng: np.random.Generator) -> Material:
    return Material(ka=float(rng.uniform()), kd=float(rng.uniform()), ks=float(rng.uniform()),
                    n=float(rng.choice([0.0, 1.0, rng.uniform(1, 200)])),
                    Os=tuple(rng.uniform(0, 1, 3)), emission=tuple(rng.uniform(0, 0.2, 3)))


_PROGRAMS: dict = {}


def _harness(ctx, lights: list[Light] | None, specular: str):
    """The include compiled as the parity harness: driven by uniforms (``lights`` None), or
    specialized to ``lights`` exactly as the renderer compiles it (``#define NUM_LIGHTS``,
    ``LIGHT_KINDS``, ``LIGHT_ATTENUATIONS``, ``SPECULAR_MODEL``)."""
    defines = None
    if lights is not None:
        defines = Renderer.light_defines(Renderer.light_signature_of(lights, specular))
    key = repr(defines)
    if key not in _PROGRAMS:
        register_includes(ctx)
        _PROGRAMS[key] = ctx.program(
            vertex_shader=(SHADERS / "parity.vert").read_text(),
            fragment_shader=with_defines((SHADERS / "parity.frag").read_text(), defines))
    target = ctx.simple_framebuffer((N_POINTS, 1), components=4, dtype="f4")
    return ctx, _PROGRAMS[key], target


@pytest.fixture(params=["uniforms", "specialized"])
def harness(gl_ctx, request):
    return lambda lights, specular: _harness(
        gl_ctx, lights if request.param == "specialized" else None, specular)


def _gpu_shade(harness, points, normals, od, eye, material, lights, Ia, specular):
    ctx, program, target = harness
    data = np.concatenate([points, normals, od], axis=1).astype("f4")
    vbo = ctx.buffer(data.tobytes())
    vao = ctx.vertex_array(program, [(vbo, "3f 3f 3f", "in_position", "in_normal", "in_od")])
    set_uniform(program, "u_count", N_POINTS)
    set_uniform(program, "u_eye", tuple(eye))
    set_uniform(program, "u_Ia", tuple(Ia))
    set_uniform(program, "u_ambient_on", 1.0)
    set_uniform(program, "u_specular_model", 1 if specular == "blinn" else 0)
    Renderer.set_material_uniforms(program, material)
    write_light_uniforms(program, lights)
    target.use()
    target.clear()
    ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND)
    vao.render(moderngl.POINTS)
    out = np.frombuffer(target.read(components=4, dtype="f4"), dtype="f4").reshape(-1, 4)
    vao.release()
    vbo.release()
    return out[:, :3]


@pytest.mark.parametrize("specular", ["phong", "blinn"])
@pytest.mark.parametrize("kind", ["point", "directional", "spot"])
@pytest.mark.parametrize("attenuation", ["none", "inverse_square", "lecture"])
def test_glsl_matches_numpy(harness, np_rng, specular, kind, attenuation):
    for _ in range(4):
        points = np_rng.uniform(-1, 1, (N_POINTS, 3))
        normals = normalize(np_rng.normal(size=(N_POINTS, 3)))
        od = np_rng.uniform(0, 1, (N_POINTS, 3))
        eye = np_rng.uniform(-4, 4, 3)
        material = _random_material(np_rng)
        lights = [_random_light(np_rng, kind, attenuation) for _ in range(3)]
        Ia = np_rng.uniform(0, 0.5, 3)
        gpu = _gpu_shade(harness(lights, specular), points, normals, od, eye, material, lights,
                         Ia, specular)
        ref = shade(points.astype("f4").astype(np.float64), normals.astype("f4"), eye, material,
                    lights, Ia, specular, od=od.astype("f4"))
        np.testing.assert_allclose(gpu, ref, rtol=1e-4, atol=1e-5)


def test_eight_lights_and_more(harness, np_rng):
    """All MAX_LIGHTS slots are summed (the renderer promises at least 8 at once)."""
    points = np_rng.uniform(-1, 1, (N_POINTS, 3))
    normals = normalize(np_rng.normal(size=(N_POINTS, 3)))
    od = np.ones((N_POINTS, 3))
    material = Material(ka=0.0, kd=1.0, ks=0.0)
    lights = [_random_light(np_rng, "directional", "none") for _ in range(16)]
    gpu = _gpu_shade(harness(lights, "phong"), points, normals, od, np.zeros(3) + 5, material,
                     lights, np.zeros(3), "phong")
    ref = shade(points, normals, np.zeros(3) + 5, material, lights, np.zeros(3), od=od)
    fewer = shade(points, normals, np.zeros(3) + 5, material, lights[:8], np.zeros(3), od=od)
    np.testing.assert_allclose(gpu, ref, rtol=1e-4, atol=1e-5)
    assert np.abs(ref - fewer).max() > 0.1  # the last 8 lights really contribute


@pytest.mark.parametrize("specular", ["phong", "blinn"])
def test_mixed_light_kinds_in_one_program(harness, np_rng, specular):
    """A specialized program folds each light's own kind and attenuation, not the first's."""
    lights = [_random_light(np_rng, "point", "lecture"), _random_light(np_rng, "spot", "none"),
              _random_light(np_rng, "directional", "inverse_square"),
              _random_light(np_rng, "spot", "inverse_square")]
    for light in lights:
        light.cone_angle = 80.0  # wide cones: the spots light most points
    points = np_rng.uniform(-1, 1, (N_POINTS, 3))
    normals = normalize(np_rng.normal(size=(N_POINTS, 3)))
    od = np_rng.uniform(0, 1, (N_POINTS, 3))
    material = _random_material(np_rng)
    eye = np.array([0.5, 2.0, 4.0])
    gpu = _gpu_shade(harness(lights, specular), points, normals, od, eye, material, lights,
                     np.full(3, 0.1), specular)
    ref = shade(points.astype("f4").astype(np.float64), normals.astype("f4"), eye, material,
                lights, np.full(3, 0.1), specular, od=od.astype("f4"))
    np.testing.assert_allclose(gpu, ref, rtol=1e-4, atol=1e-5)


TERM_CASES = ["ambient", "diffuse", "specular", "attenuation", "shadow"]


@pytest.mark.parametrize("term", TERM_CASES + ["diffuse+specular"])
@pytest.mark.parametrize("specular", ["phong", "blinn"])
def test_a_term_switched_off_matches_numpy(harness, np_rng, term, specular):
    """lighting.glsl's u_terms_off bits leave out what shade_terms(off=...) leaves out: each
    term alone (and two at once), with S_i given per light and lecture attenuation, so every
    switch has something to switch (issue 22: a click on the caption's term)."""
    from shadelab.shading.codes import terms_mask

    off = tuple(term.split("+"))
    points = np_rng.uniform(-1, 1, (N_POINTS, 3))
    normals = normalize(np_rng.normal(size=(N_POINTS, 3)))
    od = np_rng.uniform(0, 1, (N_POINTS, 3))
    eye = np.array([0.3, 2.5, 4.0])
    material = Material(ka=0.4, kd=0.6, ks=0.5, n=12.0, Os=(0.9, 0.8, 0.7))
    lights = [_random_light(np_rng, "point", "lecture") for _ in range(3)]
    for light in lights:
        light.c1, light.c2, light.c3 = 1.0, 0.3, 0.2    # f_att well below 1 at these distances
    shadow = [0.0, 1.0, 0.5]
    ctx, program, target = harness(lights, specular)
    set_uniform(program, "u_terms_off", terms_mask(off))
    try:
        data = np.concatenate([points, normals, od], axis=1).astype("f4")
        vbo = ctx.buffer(data.tobytes())
        vao = ctx.vertex_array(program, [(vbo, "3f 3f 3f", "in_position", "in_normal", "in_od")])
        set_uniform(program, "u_count", N_POINTS)
        set_uniform(program, "u_eye", tuple(eye))
        set_uniform(program, "u_Ia", (0.3, 0.25, 0.2))
        set_uniform(program, "u_ambient_on", 1.0)
        set_uniform(program, "u_specular_model", 1 if specular == "blinn" else 0)
        Renderer.set_material_uniforms(program, material)
        write_light_uniforms(program, lights, shadow)
        target.use()
        target.clear()
        ctx.disable(moderngl.DEPTH_TEST | moderngl.BLEND)
        vao.render(moderngl.POINTS)
        gpu = np.frombuffer(target.read(components=4, dtype="f4"), dtype="f4").reshape(-1, 4)
        vao.release()
        vbo.release()
    finally:
        set_uniform(program, "u_terms_off", 0)   # the cached program serves other tests
    p, n, o = points.astype("f4").astype(np.float64), normals.astype("f4"), od.astype("f4")
    s = [np.full(N_POINTS, v) for v in shadow]
    ref = shade(p, n, eye, material, lights, (0.3, 0.25, 0.2), specular, s, od=o, off=off)
    whole = shade(p, n, eye, material, lights, (0.3, 0.25, 0.2), specular, s, od=o)
    np.testing.assert_allclose(gpu[:, :3], ref, rtol=1e-4, atol=1e-5)
    assert np.abs(whole - ref).max() > 0.02   # the switch changed the image
