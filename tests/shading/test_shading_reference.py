"""Closed-form checks of every term of the lecture's equation (shadelab.shading.reference)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shadelab.scene.model import Light, Material
from shadelab.shading import reference as ref

UP = np.array([0.0, 0.0, 1.0])


def unit(*v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def test_lambert_is_cosine_clamped():
    for deg in (0, 30, 60, 89):
        t = math.radians(deg)
        assert ref.lambert(UP, unit(math.sin(t), 0, math.cos(t))) == pytest.approx(math.cos(t))
    assert ref.lambert(UP, unit(0, 0, -1)) == 0.0


def test_reflection_vector_formula():
    L = unit(1, 0, 1)
    np.testing.assert_allclose(ref.reflect_light(UP, L), unit(-1, 0, 1), atol=1e-12)


def test_phong_specular_peaks_on_mirror_direction_and_falls_as_cos_n():
    L = unit(1, 0, 1)
    R = unit(-1, 0, 1)
    assert ref.phong_specular(UP, L, R, 20.0) == pytest.approx(1.0)
    t = math.radians(10)
    V = unit(-math.sin(math.radians(45) + t), 0, math.cos(math.radians(45) + t))
    assert ref.phong_specular(UP, L, V, 20.0) == pytest.approx(math.cos(t) ** 20, rel=1e-9)


def test_blinn_uses_halfway_vector():
    L, V = unit(1, 0, 1), unit(0, 0, 1)
    H = unit(*(L + V))
    np.testing.assert_allclose(ref.halfway(L, V), H)
    assert ref.blinn_phong_specular(UP, L, V, 8.0) == pytest.approx(H[2] ** 8)


def test_halfway_guard_when_light_opposite_eye():
    L = unit(1, 0, 0)
    assert np.all(ref.halfway(L, -L) == 0.0)
    assert np.isfinite(ref.blinn_phong_specular(UP, L, -L, 10.0))


def test_specular_is_zero_for_light_behind_surface():
    assert ref.phong_specular(UP, unit(1, 0, -0.1), unit(-1, 0, 0.1), 1.0) == 0.0
    assert ref.blinn_phong_specular(UP, unit(1, 0, -0.1), unit(0, 0, 1), 1.0) == 0.0


def test_shininess_zero_is_one_inside_lobe_and_zero_outside():
    assert ref.phong_specular(UP, unit(0, 0, 1), unit(0, 0, 1), 0.0) == 1.0
    assert ref.phong_specular(UP, unit(1, 0, 1), unit(1, 0, 0.01), 0.0) == 0.0


@pytest.mark.parametrize("d", [0.5, 1.0, 2.0, 10.0])
def test_attenuation_forms(d):
    assert ref.attenuation(d, "none", 0, 0, 0) == 1.0
    assert ref.attenuation(d, "inverse_square", 0, 0, 0) == pytest.approx(1 / d**2)
    c1, c2, c3 = 0.25, 0.1, 0.05
    expected = min(1.0 / (c1 + c2 * d + c3 * d * d), 1.0)
    assert ref.attenuation(d, "lecture", c1, c2, c3) == pytest.approx(expected)


def test_lecture_attenuation_clamp_and_zero_constants():
    light = Light(attenuation="lecture", c1=0.1, c2=0.0, c3=0.0)
    assert ref.attenuation(3.0, "lecture", 0.1, 0.0, 0.0) == 1.0  # min(10, 1)
    assert bool(ref.attenuation_clamped(3.0, light))
    assert ref.attenuation(3.0, "lecture", 0.0, 0.0, 0.0) == 1.0  # c = 0: no division by 0
    assert ref.attenuation(np.inf, "inverse_square", 0, 0, 0) == 1.0  # directional


def test_spot_cone_and_falloff():
    axis = unit(0, 0, -1)
    inside = unit(math.sin(math.radians(10)), 0, math.cos(math.radians(10)))  # to the light
    outside = unit(math.sin(math.radians(40)), 0, math.cos(math.radians(40)))
    cos_cone = math.cos(math.radians(30))
    assert ref.spot_factor(inside, axis, cos_cone, 4.0) == pytest.approx(
        math.cos(math.radians(10)) ** 4)
    assert ref.spot_factor(outside, axis, cos_cone, 4.0) == 0.0


def test_full_equation_two_colored_lights():
    """I = Ia ka Od + sum f_att Ip [kd Od N.L + ks Os (R.V)^n], by hand, per channel."""
    m = Material(ka=0.2, kd=0.5, ks=0.3, n=5.0, Od=(0.9, 0.5, 0.1), Os=(1.0, 0.8, 0.6))
    p = np.zeros(3)
    eye = np.array([0.0, 0.0, 4.0])
    l1 = Light(kind="point", position=(0.0, 3.0, 4.0), Ip=(1.0, 0.5, 0.25),
               attenuation="lecture", c1=0.5, c2=0.1, c3=0.01)
    l2 = Light(kind="directional", direction=(0.0, 0.0, -1.0), Ip=(0.2, 0.4, 0.6))
    Ia = np.array([0.1, 0.2, 0.3])
    got = ref.shade(p, UP, eye, m, [l1, l2], Ia)
    Od, Os = np.array(m.Od), np.array(m.Os)
    L1 = unit(0, 3, 4)
    f1 = min(1 / (0.5 + 0.1 * 5 + 0.01 * 25), 1)
    R1 = 2 * UP * L1[2] - L1
    expected = Ia * m.ka * Od
    expected += f1 * np.array(l1.Ip) * (m.kd * Od * L1[2] + m.ks * Os * max(R1[2], 0) ** 5)
    expected += np.array(l2.Ip) * (m.kd * Od * 1.0 + m.ks * Os * 1.0)
    np.testing.assert_allclose(got, expected, rtol=1e-12)


def test_shadow_factor_removes_a_light_but_not_ambient():
    m = Material(ka=0.5, kd=0.5, ks=0.5)
    light = Light(kind="directional", direction=(0, 0, -1))
    lit = ref.shade(np.zeros(3), UP, UP * 3, m, [light], (1, 1, 1), shadow=[np.array(1.0)])
    dark = ref.shade(np.zeros(3), UP, UP * 3, m, [light], (1, 1, 1), shadow=[np.array(0.0)])
    np.testing.assert_allclose(dark, 0.5 * np.ones(3))
    assert np.all(lit > dark)


def test_terms_sum_to_total_and_never_nan(np_rng):
    m = Material(ka=0.3, kd=0.6, ks=0.9, n=0.0)
    lights = [Light(position=tuple(np_rng.normal(size=3))) for _ in range(3)]
    p = np_rng.normal(size=(100, 3))
    n = ref.normalize(np_rng.normal(size=(100, 3)))
    terms = ref.shade_terms(p, n, p[0], m, lights, (0.2, 0.2, 0.2))  # eye on a surface point
    total = terms.total
    assert np.all(np.isfinite(total)) and np.all(total >= 0)
    manual = terms.ambient + sum(t.diffuse + t.specular for t in terms.lights)
    np.testing.assert_allclose(total, manual)
