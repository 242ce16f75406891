"""The path tracer's sampled glossy lobe (shadelab.raytrace.glossy) against closed forms and a
brute-force estimator, its numba and numpy implementations against each other, and the
ks = 0 scenes unchanged."""

from __future__ import annotations

import math

import numba as nb
import numpy as np
import pytest

from shadelab.raytrace import glossy, vertex
from shadelab.raytrace.pathtrace import (
    PathTracer,
    glossy_directions,
    glossy_lobe_pdf,
    render_pathtraced,
)
from shadelab.raytrace.scatter import _sample_cosine_hemisphere
from shadelab.raytrace.vertex import _emission_weight, _specular_lobe
from shadelab.scene.model import Camera, Material, Object, Scene
from shadelab.scene.preset import load_preset

OS = (1.0, 0.8, 0.6)   # specular color of the glossy materials below
Z_BOUND = 4.0          # |mean - expected| in standard errors (a fixed seed: no flakes)
LAMP_X = (-1.2, -0.2)  # the lamp's x range (y = 1, |z| < 0.5)


def _quad(material: str, y: float, half: float) -> Object:
    return Object(shape="quad", material=material,
                  vertices=[[-half, y, half], [half, y, half], [half, y, -half],
                            [-half, y, -half]])


def _lobe(wi: np.ndarray, n: np.ndarray, v: np.ndarray, shininess: float,
          specular: str) -> np.ndarray:
    """The lecture's (R.wi)^n or (N.H)^n, written here from the lecture (not the kernels)."""
    if specular == "blinn":
        h = wi + v
        h /= np.linalg.norm(h, axis=-1, keepdims=True)
        c = h @ n
    else:
        c = wi @ (2.0 * (n @ v) * n - v)
    return np.where(c > 0.0, np.abs(c) ** shininess, 0.0)


def _albedo(theta_o: float, shininess: float, specular: str) -> float:
    """a(wo) / (ks Os) = 1/pi * integral over the hemisphere of lobe(wi) dwi, midpoint rule
    on a (theta, phi) grid (1600 x 3200)."""
    th = (np.arange(1600) + 0.5) * (0.5 * np.pi / 1600)
    ph = (np.arange(3200) + 0.5) * (2.0 * np.pi / 3200)
    t, p = np.meshgrid(th, ph, indexing="ij")
    wi = np.stack([np.sin(t) * np.cos(p), np.cos(t), np.sin(t) * np.sin(p)], axis=-1)
    v = np.array([math.sin(theta_o), math.cos(theta_o), 0.0])
    lobe = _lobe(wi, np.array([0.0, 1.0, 0.0]), v, shininess, specular)
    return float((lobe * np.sin(t)).sum() * (0.5 * np.pi / 1600) * (2.0 * np.pi / 3200)
                 / np.pi)


def _rays(point, theta_o: float, count: int):
    """count copies of the camera ray that reaches ``point`` at theta_o from +y (in xy)."""
    v = np.array([math.sin(theta_o), math.cos(theta_o), 0.0])
    o = np.asarray(point, float) + 0.8 * v
    return np.tile(o, (count, 1)), np.tile(-v, (count, 1))


def _z(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|mean(a) - b| in standard errors of a's mean, per channel, for samples a (N, 3) and
    an expected b (3,); or against the mean of samples b (M, 3) in combined ones."""
    se2 = a.var(axis=0) / len(a)
    if b.ndim == 2:
        se2 = se2 + b.var(axis=0) / len(b)
        b = b.mean(axis=0)
    return np.abs(a.mean(axis=0) - b) / np.sqrt(se2)


# ---------------------------------------------------------------- closed form: the albedo

@pytest.mark.parametrize("local", ["numba", "numpy"])
@pytest.mark.parametrize("specular, shininess, theta_deg", [
    ("phong", 20.0, 0.0), ("phong", 20.0, 65.0), ("blinn", 40.0, 0.0), ("blinn", 40.0, 70.0)])
def test_glossy_quad_in_an_emitting_box_is_le_times_the_albedo(local, specular, shininess,
                                                                theta_deg):
    """A purely glossy quad (kd = 0, kr = 0) inside a closed box of uniform radiance Le that
    reflects nothing: every direction above the quad sees Le, so L = Le a(wo) with a the
    BRDF's directional albedo (numpy quadrature above, independent of the kernels). 60 000
    paths at one vertex: within Z_BOUND standard errors and 1 %."""
    le = np.array([2.0, 1.0, 0.5])
    glossy_mat = Material(ka=0.0, kd=0.0, ks=0.8, n=shininess, Os=OS, kr=0.0)
    box = Material(ka=0.0, kd=0.0, ks=0.0, emission=tuple(le))
    scene = Scene(Ia=(0.0, 0.0, 0.0), lights=[], materials={"g": glossy_mat, "box": box},
                  camera=Camera(eye=(0.0, 0.5, 0.5), target=(0.0, -0.5, 0.0)),
                  objects=[Object(shape="box", material="box", extents=(2.0, 2.0, 2.0)),
                           _quad("g", -0.5, 0.6)])
    scene.render.specular = specular
    theta = math.radians(theta_deg)
    o, d = _rays((0.1, -0.5, 0.05), theta, 60_000)
    got = PathTracer(scene, local=local).radiance(o, d, np.random.default_rng(11))
    expected = le * 0.8 * np.array(OS) * _albedo(theta, shininess, specular)
    assert np.all(_z(got, expected) < Z_BOUND), (got.mean(axis=0), expected)
    np.testing.assert_allclose(got.mean(axis=0), expected, rtol=0.01)


@pytest.mark.parametrize("specular", ["phong", "blinn"])
@pytest.mark.parametrize("shininess", [0.0, 3.0, 40.0, 500.0])
def test_lobe_weight_is_the_albedo_at_normal_incidence(specular, shininess):
    """glossy.lobe_weight's closed forms, 2 / (n + 1) and 8 (1 - 2^-(n/2+1)) / (n + 2), are
    the quadrature's a(N) / (ks Os) (to 1e-4)."""
    got = glossy.lobe_weight(np.array([1.0]), np.array([shininess]), specular == "blinn")[0]
    assert got == pytest.approx(_albedo(0.0, shininess, specular), rel=1e-4)


# ---------------------------------------------------------------- brute force: uniform sampling

def _lamp_scene(specular: str, walls: bool = False) -> Scene:
    """A diffuse + glossy floor (y = 0) under a 1 x 1 emitting square at y = 1, shifted so the
    highlight of the view below falls across the lamp's edge; ``walls`` adds a diffuse wall
    and a point light (inter-reflection and the delta-light term)."""
    floor = Material(ka=0.0, kd=0.3, Od=(0.8, 0.7, 0.6), ks=0.7, n=30.0, Os=OS, kr=0.0)
    lamp = Material(ka=0.0, kd=0.0, ks=0.0, emission=(4.0, 3.0, 2.0))
    objects = [_quad("floor", 0.0, 3.0),
               Object(shape="quad", material="lamp",
                      vertices=[[LAMP_X[0], 1, -0.5], [LAMP_X[1], 1, -0.5],
                                [LAMP_X[1], 1, 0.5], [LAMP_X[0], 1, 0.5]])]
    materials = {"floor": floor, "lamp": lamp}
    lights = []
    if walls:
        from shadelab.scene.model import Light

        materials["wall"] = Material(ka=0.0, kd=0.9, Od=(0.9, 0.9, 0.9), ks=0.3, n=8.0)
        objects.append(Object(shape="quad", material="wall",
                              vertices=[[1.5, 0, -2], [1.5, 0, 2], [1.5, 2, 2], [1.5, 2, -2]]))
        lights = [Light(kind="point", position=(0.0, 1.5, 1.0), Ip=(0.5, 0.5, 0.5))]
    scene = Scene(Ia=(0.0, 0.0, 0.0), lights=lights, materials=materials,
                  camera=Camera(eye=(-1.0, 1.0, 0.0), target=(0.5, 0.0, 0.0)), objects=objects)
    scene.render.specular = specular
    return scene


def _uniform_hemisphere_estimate(scene: Scene, point, theta_o: float, count: int,
                                 rng) -> np.ndarray:
    """Per-sample estimates of L at ``point`` on the floor: uniform directions (pdf 1 / 2 pi),
    f cos = (rho cos_i + ks Os lobe) / pi, Le where the direction meets the lamp."""
    floor, lamp = scene.materials["floor"], scene.materials["lamp"]
    z = rng.random(count)
    phi = 2.0 * np.pi * rng.random(count)
    r = np.sqrt(1.0 - z * z)
    wi = np.stack([r * np.cos(phi), z, r * np.sin(phi)], axis=1)
    v = np.array([math.sin(theta_o), math.cos(theta_o), 0.0])
    s = 1.0 / wi[:, 1]
    x, zz = point[0] + s * wi[:, 0], point[2] + s * wi[:, 2]
    seen = (x > LAMP_X[0]) & (x < LAMP_X[1]) & (np.abs(zz) < 0.5)
    rho = floor.kd * np.array(floor.Od)
    ks_os = floor.ks * np.array(floor.Os)
    lobe = _lobe(wi, np.array([0.0, 1.0, 0.0]), v, floor.n, scene.render.specular)
    f_cos = (rho[None] * wi[:, 1:2] + ks_os[None] * lobe[:, None]) / np.pi
    return 2.0 * np.pi * f_cos * np.array(lamp.emission)[None] * seen[:, None]


@pytest.mark.parametrize("local", ["numba", "numpy"])
@pytest.mark.parametrize("specular", ["phong", "blinn"])
def test_sampled_lobe_agrees_with_uniform_hemisphere_sampling(local, specular):
    """One floor vertex under a square lamp, its highlight across the lamp's edge: the path
    tracer (NEE + the sampled lobes, MIS) against 400 000 uniform-hemisphere samples of the
    same BRDF, within 3 combined standard errors per channel."""
    scene = _lamp_scene(specular)
    point, theta = (0.2, 0.0, 0.1), math.radians(55.0)
    o, d = _rays(point, theta, 80_000)
    got = PathTracer(scene, local=local).radiance(o, d, np.random.default_rng(5))
    brute = _uniform_hemisphere_estimate(scene, point, theta, 400_000,
                                         np.random.default_rng(6))
    assert np.all(_z(got, brute) < 3.0), (got.mean(axis=0), brute.mean(axis=0))
    # the highlight matters here: the same vertex with ks = 0 is darker by > 20 %
    matte = _lamp_scene(specular)
    matte.materials["floor"].ks = 0.0
    dull = PathTracer(matte, local=local).radiance(o[:20_000], d[:20_000],
                                                   np.random.default_rng(5))
    assert np.all(dull.mean(axis=0) < 0.8 * got.mean(axis=0))


# ---------------------------------------------------------------- numba against numpy

@pytest.mark.parametrize("blinn", [False, True])
def test_lobe_helpers_numba_equal_numpy(blinn):
    """glossy.sample_lobe / lobe_pdf (numba) and their numpy twins on 300 random frames and
    uniforms: the same directions, weights, lobes and pdfs to 1e-9 (relative)."""
    rng = np.random.default_rng(21)
    m = 300
    n = rng.normal(size=(m, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    v = rng.normal(size=(m, 3))
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    v = np.where((np.einsum("ij,ij->i", n, v) < 0.0)[:, None], -v, v)
    shininess = rng.choice([0.0, 1.0, 7.5, 60.0, 900.0], size=m)
    u1, u2 = rng.random(m), rng.random(m)
    wi, w = glossy_directions(n, v, shininess, blinn, u1, u2)
    lobe, pdf = glossy_lobe_pdf(wi, n, v, shininess, blinn)
    for i in range(m):
        got = glossy.sample_lobe(u1[i], u2[i], *n[i], *v[i], shininess[i], blinn)
        np.testing.assert_allclose(got[:3], wi[i], rtol=1e-9, atol=1e-12)
        assert got[3] == pytest.approx(np.broadcast_to(w, m)[i], rel=1e-9, abs=1e-12)
        got_lobe, got_pdf = glossy.lobe_pdf(*wi[i], *n[i], *v[i], shininess[i], blinn)
        assert got_lobe == pytest.approx(lobe[i], rel=1e-9, abs=1e-300)
        assert got_pdf == pytest.approx(pdf[i], rel=1e-9, abs=1e-300)
    assert np.all(np.abs(np.linalg.norm(wi, axis=1) - 1.0) < 1e-12)


@pytest.mark.parametrize("specular", ["phong", "blinn"])
def test_numba_and_numpy_path_tracers_agree_with_glossy_inter_reflection(specular):
    """The lamp scene with a diffuse + glossy wall and a point light (multi-bounce glossy and
    diffuse paths, the delta-light term, NEE, roulette): one vertex's mean radiance from the
    two implementations within Z_BOUND combined standard errors (60 000 paths each)."""
    scene = _lamp_scene(specular, walls=True)
    o, d = _rays((0.2, 0.0, 0.1), math.radians(55.0), 60_000)
    a = PathTracer(scene, local="numba").radiance(o, d, np.random.default_rng(7))
    b = PathTracer(scene, local="numpy").radiance(o, d, np.random.default_rng(8))
    assert np.all(_z(a, b) < Z_BOUND), (a.mean(axis=0), b.mean(axis=0))
    assert a.mean() > 0.1


# ---------------------------------------------------------------- ks = 0: nothing changes

# The diffuse-only vertex the path tracer had before the glossy lobe (the oracle: the shared
# vertex.path_vertex and vertex._next_event must give these numbers bit for bit when ks = 0).
@nb.njit
def _diffuse_next_event(i, m, emitters, rho, beta, px, py, pz, nx, ny, nz, gx, gy, gz, prob_d,
                        eps, rnd, nee_o, nee_d, nee_t, nee_ok, nee_val):
    em_cdf, em_p0, em_e1, em_e2, em_normal, em_le, em_area = emitters
    k = np.searchsorted(em_cdf, rnd[i, 0], side="right")
    k = min(k, len(em_cdf) - 1)
    s = math.sqrt(rnd[i, 1])
    a, b = s * (1.0 - rnd[i, 2]), s * rnd[i, 2]
    qx = em_p0[k, 0] + a * em_e1[k, 0] + b * em_e2[k, 0] - px
    qy = em_p0[k, 1] + a * em_e1[k, 1] + b * em_e2[k, 1] - py
    qz = em_p0[k, 2] + a * em_e1[k, 2] + b * em_e2[k, 2] - pz
    dist = math.sqrt(qx * qx + qy * qy + qz * qz)
    if not dist > 2.0 * eps:
        return
    wx, wy, wz = qx / dist, qy / dist, qz / dist
    cos_x = nx * wx + ny * wy + nz * wz
    cos_y = abs(em_normal[k, 0] * wx + em_normal[k, 1] * wy + em_normal[k, 2] * wz)
    if not (cos_x > 0.0 and gx * wx + gy * wy + gz * wz > 0.0):
        return
    light_pdf = dist * dist / max(cos_y * em_area, 1e-300)
    scale = cos_x / (light_pdf + prob_d * cos_x / math.pi) / math.pi
    nee_ok[i] = True
    nee_o[i, 0] = px + eps * gx
    nee_o[i, 1] = py + eps * gy
    nee_o[i, 2] = pz + eps * gz
    nee_d[i, 0], nee_d[i, 1], nee_d[i, 2] = wx, wy, wz
    nee_t[i] = dist * (1.0 - 1e-4) - 2.0 * eps
    for c in range(3):
        nee_val[i, c] = beta[i, c] * rho[m, c] * em_le[k, c] * scale


@nb.njit
def _diffuse_path_vertex(out, pixel, beta, bsdf_pdf, position, normal, geo, entering, dirs, t,
                         mat, surfaces, emitters, eps, rnd, roulette):
    rho, kr, kt, ior, emission = surfaces
    em_area = emitters[6]
    n = len(pixel)
    nee_o = np.empty((n, 3))
    nee_d = np.empty((n, 3))
    nee_t = np.empty(n)
    nee_ok = np.zeros(n, np.bool_)
    nee_val = np.zeros((n, 3))
    new_o = np.empty((n, 3))
    new_d = np.empty((n, 3))
    new_beta = np.empty((n, 3))
    new_pdf = np.zeros(n)
    alive = np.zeros(n, np.bool_)
    n_em = len(emitters[0])
    for i in range(n):
        m = mat[i]
        px, py, pz = position[i, 0], position[i, 1], position[i, 2]
        nx, ny, nz = normal[i, 0], normal[i, 1], normal[i, 2]
        gx, gy, gz = geo[i, 0], geo[i, 1], geo[i, 2]
        dx, dy, dz = dirs[i, 0], dirs[i, 1], dirs[i, 2]
        if max(emission[m, 0], max(emission[m, 1], emission[m, 2])) > 0.0:
            w = _emission_weight(bsdf_pdf[i], t[i], abs(gx * dx + gy * dy + gz * dz), em_area)
            for c in range(3):
                out[pixel[i], c] += beta[i, c] * emission[m, c] * w
        p_d = (rho[m, 0] + rho[m, 1] + rho[m, 2]) / 3.0
        total = p_d + kr[m] + kt[m]
        prob_d = p_d / total if total > 0.0 else 0.0
        if n_em > 0 and p_d > 0.0:
            _diffuse_next_event(i, m, emitters, rho, beta, px, py, pz, nx, ny, nz, gx, gy, gz,
                                prob_d, eps, rnd, nee_o, nee_d, nee_t, nee_ok, nee_val)
        if total <= 0.0:
            continue
        u = rnd[i, 3] * total
        side = 1.0
        if u < p_d:
            ox, oy, oz, cos_o = _sample_cosine_hemisphere(rnd[i, 4], rnd[i, 5], nx, ny, nz)
            if ox * gx + oy * gy + oz * gz <= 0.0:
                continue
            for c in range(3):
                new_beta[i, c] = beta[i, c] * rho[m, c] / prob_d
            new_pdf[i] = prob_d * cos_o / math.pi
        else:
            ox, oy, oz, side, weight, prob = _specular_lobe(u, p_d, kr[m], kt[m], ior[m],
                                                            entering[i], total, dx, dy, dz,
                                                            nx, ny, nz, rnd[i, 4])
            for c in range(3):
                new_beta[i, c] = beta[i, c] * weight / prob
        if roulette:
            q = min(max(new_beta[i, 0], max(new_beta[i, 1], new_beta[i, 2])), 0.95)
            if rnd[i, 6] >= q:
                continue
            for c in range(3):
                new_beta[i, c] /= max(q, 1e-12)
        alive[i] = True
        new_d[i, 0], new_d[i, 1], new_d[i, 2] = ox, oy, oz
        new_o[i, 0] = px + side * eps * gx
        new_o[i, 1] = py + side * eps * gy
        new_o[i, 2] = pz + side * eps * gz
    return nee_o, nee_d, nee_t, nee_ok, nee_val, new_o, new_d, new_beta, new_pdf, alive


def test_ks_zero_scenes_are_the_diffuse_only_vertex_images(monkeypatch):
    """cornell and cornell-spheres (ks = 0 everywhere): vertex.path_vertex (with the one
    shared _next_event) renders bit for bit what the diffuse-only vertex above (the path
    tracer's before the glossy lobe) does; a glossy material changes the image."""
    scenes = [load_preset("cornell"), load_preset("cornell-spheres")]
    images = [render_pathtraced(s, (16, 12), 2, seed=9) for s in scenes]

    def diffuse_only(out, pixel, beta, bsdf_pdf, position, normal, geo, entering, dirs, t,
                     mat, surfaces, lobes, emitters, eps, rnd, roulette, blinn):
        assert not lobes[2].any()
        return _diffuse_path_vertex(out, pixel, beta, bsdf_pdf, position, normal, geo,
                                    entering, dirs, t, mat, surfaces, emitters, eps, rnd,
                                    roulette)

    with monkeypatch.context() as patch:
        patch.setattr(vertex, "path_vertex", diffuse_only)
        for scene, image in zip(scenes, images, strict=True):
            np.testing.assert_array_equal(render_pathtraced(scene, (16, 12), 2, seed=9),
                                          image)
    shiny = load_preset("cornell", ["materials.white.ks=0.5", "materials.white.kr=0"])
    assert np.abs(render_pathtraced(shiny, (16, 12), 2, seed=9) - images[0]).max() > 0
