"""Light kinds as classes (shadelab.shading.lights) against closed forms, and the one packing
of materials and lights (shadelab.shading.packing): rho = kd Od computed there only, the
material's uniforms by one route."""

from __future__ import annotations

import ast
import math
import re
import struct
from pathlib import Path

import numpy as np
import pytest

import shadelab
from shadelab.scene.model import LIGHT_KINDS, Light, Material
from shadelab.shading import codes, packing
from shadelab.shading.lights import (
    DirectionalLight,
    PointLight,
    SpotLight,
    light_kind,
)

PACKAGE = Path(shadelab.__file__).resolve().parent
P = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])


def test_each_kind_string_is_one_class_with_its_code():
    assert [type(light_kind(Light(kind=k))) for k in LIGHT_KINDS] == [
        PointLight, DirectionalLight, SpotLight]
    assert codes.LIGHT_KIND_CODES == {"point": 0, "directional": 1, "spot": 2}
    table = packing.light_table([Light(kind=k, direction=(0, -1, 0)) for k in LIGHT_KINDS])
    assert table[:, packing.L_KIND].tolist() == [0.0, 1.0, 2.0]
    kinds = {k: light_kind(Light(kind=k)) for k in LIGHT_KINDS}
    assert {k: (v.at_infinity, v.aimed, v.has_cone) for k, v in kinds.items()} == {
        "point": (False, False, False), "directional": (True, True, False),
        "spot": (False, True, True)}


def test_point_light_vectors_and_attenuation_closed_form():
    kind = light_kind(Light(kind="point", position=(0.0, 2.0, 0.0),
                            attenuation="inverse_square"))
    to_light, d = kind.to_light(P)
    np.testing.assert_allclose(to_light[0], (0.0, 1.0, 0.0), atol=1e-15)
    np.testing.assert_allclose(to_light[1], np.array([-1.0, 2.0, 0.0]) / math.sqrt(5),
                               atol=1e-15)
    np.testing.assert_allclose(d, (2.0, math.sqrt(5)), rtol=1e-15)
    np.testing.assert_allclose(kind.attenuation(d), (0.25, 0.2), rtol=1e-12)
    np.testing.assert_array_equal(kind.spot(to_light), (1.0, 1.0))
    np.testing.assert_array_equal(kind.homogeneous(), (0.0, 2.0, 0.0, 1.0))
    np.testing.assert_array_equal(kind.end(), (0.0, 2.0, 0.0))


def test_directional_light_is_at_infinity():
    kind = light_kind(Light(kind="directional", direction=(0.0, -2.0, 0.0),
                            attenuation="inverse_square"))
    to_light, d = kind.to_light(P)
    np.testing.assert_array_equal(to_light, [[0.0, 1.0, 0.0]] * 2)
    assert np.all(np.isinf(d))
    np.testing.assert_array_equal(kind.attenuation(d), (1.0, 1.0))
    np.testing.assert_array_equal(kind.homogeneous(), (0.0, 1.0, 0.0, 0.0))
    assert kind.end() is None and kind.at_infinity and kind.aimed


def test_spot_cone_closed_form():
    kind = light_kind(Light(kind="spot", position=(0.0, 2.0, 0.0), direction=(0.0, -1.0, 0.0),
                            cone_angle=30.0, spot_exponent=4.0))
    to_light, _ = kind.to_light(np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [3.0, 0.0, 0.0]]))
    cos_phi = 2.0 / math.sqrt(2.0 ** 2 + 0.5 ** 2)  # 14 degrees: inside; 56 degrees: outside
    np.testing.assert_allclose(kind.spot(to_light), (1.0, cos_phi ** 4, 0.0), rtol=1e-12)


def test_reflectance_and_the_material_uniforms_one_route():
    m = Material(ka=0.1, kd=0.6, ks=0.3, n=20.0, Od=(0.5, 0.25, 1.0), Os=(1.0, 0.5, 0.5),
                 emission=(0.0, 0.0, 0.2))
    packed = packing.pack_material(m)
    np.testing.assert_array_equal(packing.reflectance(m), (0.3, 0.15, 0.6))
    np.testing.assert_array_equal(packed.rho, packing.reflectance(m))
    raw = packing.material_uniforms(packed)
    assert raw["u_kd"] == struct.pack("f", 0.6)
    assert raw["u_Od"] == np.float32([0.5, 0.25, 1.0]).tobytes()
    ip_s = np.array([[1.0, 2.0, 4.0], [0.5, 0.5, 0.5]])
    folded = packing.premultiplied_uniforms(packed, np.array([0.2, 0.2, 0.2]), ip_s, 1.0)
    np.testing.assert_array_equal(folded["u_light_diffuse"],
                                  np.float32(ip_s * (0.6 * np.array([0.5, 0.25, 1.0]))))
    np.testing.assert_allclose(folded["u_ambient"], (0.01, 0.005, 0.22), rtol=1e-6)


@pytest.mark.parametrize("folder", ["raster", "raytrace", "radiosity", "shading", "pipelines",
                                    "lab", "bench", "studies", "ui"])
def test_rho_is_computed_in_packing_only(folder):
    """No kd * Od outside shading/packing.py (the reference's per-point equation aside)."""
    pattern = re.compile(r"\.kd\s*\*|np\.multiply\(\w+\.kd|\bkd\s*\*\s*od\b|\bkd\[[^]]*\]\s*\*")
    skip = {"packing.py", "reference.py", "kernels.py"}  # the equation's own products
    found = [f"{p.name}:{i}" for p in (PACKAGE / folder).rglob("*.py") if p.name not in skip
             for i, line in enumerate(p.read_text().splitlines(), 1) if pattern.search(line)]
    assert found == []


def _kind_string_tests(path: Path) -> list[str]:
    """``<x>.kind == "spot"``, ``<x>.kind in ("point", "spot")``... with a light kind's name."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if not isinstance(node, ast.Compare):
            continue
        sides = [node.left, *node.comparators]
        if not any(isinstance(s, ast.Attribute) and s.attr == "kind" for s in sides):
            continue
        for side in sides:
            items = side.elts if isinstance(side, (ast.Tuple, ast.List, ast.Set)) else [side]
            if any(isinstance(i, ast.Constant) and i.value in LIGHT_KINDS for i in items):
                found.append(f"{path.relative_to(PACKAGE)}:{node.lineno}")
                break
    return found


def test_light_kinds_are_tested_through_their_classes_only():
    """No light kind string compared outside shading/lights.py and scene/ (the preset's own
    names): the viewer, the probe and the renderers ask ``light_kind(light)``
    (``at_infinity``, ``aimed``, ``has_cone``, ``to_light``...). geometry/silhouette.py takes
    the kind as a string argument (a pure layer below shading) and is not a ``.kind`` test."""
    files = [p for p in PACKAGE.rglob("*.py")
             if p.relative_to(PACKAGE).parts[0] != "scene" and p.name != "lights.py"]
    assert any(p.name == "gizmos.py" for p in files) and any(p.name == "probe.py" for p in files)
    assert [hit for p in sorted(files) for hit in _kind_string_tests(p)] == []
