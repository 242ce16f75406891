"""The equation's terms switched off one by one (issue 22, shade_terms(off=...)): each additive
term leaves by exactly its own contribution, f_att off is attenuation "none", S_i off is no
shadow; the names are checked."""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.scene.model import Light, Material
from shadelab.shading.codes import TERM_BITS, TERMS, glsl_defines, terms_mask
from shadelab.shading.reference import normalize, shade, shade_terms


@pytest.fixture
def setup(np_rng):
    points = np_rng.uniform(-1, 1, (200, 3))
    normals = normalize(np_rng.normal(size=(200, 3)))
    material = Material(ka=0.3, kd=0.7, ks=0.6, n=20.0, Od=(0.8, 0.5, 0.2), Os=(1.0, 0.9, 0.8),
                        emission=(0.05, 0.0, 0.0))
    lights = [Light(kind="point", position=(1.0, 3.0, 2.0), Ip=(1.0, 0.9, 0.8),
                    attenuation="lecture", c1=1.0, c2=0.2, c3=0.1),
              Light(kind="spot", position=(-2.0, 2.0, 1.0), direction=(0.6, -0.6, -0.3),
                    Ip=(0.5, 0.6, 1.2), attenuation="inverse_square", cone_angle=70.0)]
    shadow = [np_rng.uniform(0, 1, 200), np.ones(200)]
    return points, normals, np.array([0.0, 1.0, 5.0]), material, lights, (0.2, 0.2, 0.25), shadow


@pytest.mark.parametrize("term", ["ambient", "diffuse", "specular"])
def test_an_additive_term_leaves_by_exactly_its_contribution(setup, term):
    points, normals, eye, material, lights, Ia, shadow = setup
    whole = shade_terms(points, normals, eye, material, lights, Ia, "phong", shadow)
    without = shade(points, normals, eye, material, lights, Ia, "phong", shadow, off=(term,))
    if term == "ambient":
        part = whole.ambient
    else:
        part = sum(getattr(t, term) for t in whole.lights)
    assert np.abs(part).max() > 0.04                       # there is something to remove
    np.testing.assert_allclose(whole.total - without, part, rtol=1e-12, atol=1e-14)


def test_ambient_off_keeps_the_emission(setup):
    points, normals, eye, material, lights, Ia, shadow = setup
    terms = shade_terms(points, normals, eye, material, [], Ia, off=("ambient",))
    np.testing.assert_array_equal(terms.total, np.broadcast_to([0.05, 0.0, 0.0], (200, 3)))


def test_attenuation_off_is_f_att_one(setup):
    points, normals, eye, material, lights, Ia, shadow = setup
    off = shade_terms(points, normals, eye, material, lights, Ia, "blinn", shadow,
                      off=("attenuation",))
    for light in lights:
        light.attenuation = "none"
    none = shade(points, normals, eye, material, lights, Ia, "blinn", shadow)
    np.testing.assert_allclose(off.total, none, rtol=1e-12)
    assert all(np.all(t.f_att == 1.0) for t in off.lights)


def test_shadow_off_is_every_light_seen(setup):
    points, normals, eye, material, lights, Ia, shadow = setup
    off = shade(points, normals, eye, material, lights, Ia, "phong", shadow, terminator=0.2,
                off=("shadow",))
    lit = shade(points, normals, eye, material, lights, Ia, "phong")
    shadowed = shade(points, normals, eye, material, lights, Ia, "phong", shadow)
    np.testing.assert_array_equal(off, lit)
    assert np.abs(lit - shadowed).max() > 0.05


def test_all_terms_off_leaves_the_emission(setup):
    points, normals, eye, material, lights, Ia, shadow = setup
    out = shade(points, normals, eye, material, lights, Ia, "phong", shadow, off=TERMS)
    np.testing.assert_allclose(out, np.broadcast_to(material.emission, (200, 3)), atol=0)


def test_term_names_and_bits():
    assert TERMS == ("ambient", "diffuse", "specular", "attenuation", "shadow")
    assert terms_mask(()) == 0 and terms_mask(TERMS) == 31
    assert terms_mask(["specular", "shadow"]) == TERM_BITS["specular"] | TERM_BITS["shadow"]
    assert glsl_defines()["TERM_ATTENUATION"] == 8
    with pytest.raises(ValueError, match="term 'speculr'"):
        terms_mask(["speculr"])
