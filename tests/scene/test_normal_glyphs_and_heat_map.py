"""The normals step (issue 22, item 4): one glyph per face and one per vertex (not a bundle of
parallel per-corner glyphs), the heat map's angle between two vertex-normal rules against a
closed form, and the shipped mesh on which area weighting and the plain average disagree."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh

from shadelab.geometry.mesh import scene_meshes
from shadelab.geometry.normals import (
    angle_between_degrees,
    normal_mode_difference,
    vertex_normals,
)
from shadelab.lab import overlays
from shadelab.scene import load_preset
from shadelab.scene.model import Object, Scene

# The shipped mesh's apex: plain average vs area weighting (README of the OBJ: 37 degrees)
FAN_PYRAMID_MIN_DEGREES = 30.0


def _corner():
    """Vertex 0 shared by a large +z triangle (area 2) and a small +x triangle (area 0.5),
    both with a right angle at vertex 0."""
    v = np.array([[0, 0, 0], [2, 0, 0], [0, 2, 0], [0, 1, 0], [0, 0, 1]], float)
    f = np.array([[0, 1, 2],      # (2,0,0) x (0,2,0) = (0,0,4): +z, area 2
                  [0, 3, 4]])     # (0,1,0) x (0,0,1) = (1,0,0): +x, area 0.5
    return v, f


def test_the_heat_map_is_the_angle_between_the_two_rules_in_closed_form():
    v, f = _corner()
    # average (1, 0, 1) / sqrt 2 is 45 degrees from +z; area (0.5, 0, 2) is atan(1/4)
    expected_v0 = 45.0 - math.degrees(math.atan(0.25))          # 30.9638...
    deg = normal_mode_difference(v, f, "average", "area")
    assert deg[0] == pytest.approx(expected_v0, abs=1e-9)
    np.testing.assert_allclose(deg[1:], 0.0, atol=1e-9)         # one face each: no choice
    # the same as numpy's angle between the two normal sets
    a, b = vertex_normals(v, f, "average"), vertex_normals(v, f, "area")
    np.testing.assert_allclose(deg, np.degrees(np.arccos(np.clip(
        np.sum(a * b, axis=1), -1, 1))), atol=1e-6)
    # both corners are right angles: angle weighting is the plain average here
    np.testing.assert_allclose(normal_mode_difference(v, f, "average", "angle"), 0.0,
                               atol=1e-9)
    assert angle_between_degrees(np.array([1.0, 0, 0]), np.array([-1.0, 0, 0])) == \
        pytest.approx(180.0)
    with pytest.raises(ValueError, match="crease"):
        normal_mode_difference(v, f, "average", "crease")


def test_the_heat_map_colours_each_corner_by_its_vertex_angle():
    v, f = _corner()
    from shadelab.geometry.mesh import MeshData
    from shadelab.geometry.normals import face_normals

    fn = face_normals(v, f)
    mesh = MeshData(0, "default", v, f, np.zeros((5, 2)), fn, np.repeat(fn[:, None], 3, 1))
    degrees = overlays.normal_difference([mesh], "average", "area")
    full = overlays.heat_scale_max(float(degrees[0].max()))
    assert full == 35.0                                          # 30.96 rounded up to 5
    soup = overlays.normal_difference_soup([mesh], degrees, full)
    assert soup.shape == (6, 6)
    np.testing.assert_allclose(soup[:, :3], v[f].reshape(-1, 3))
    hot = overlays.srgb_to_linear(overlays.heat_color_srgb(degrees[0][0] / 35.0))
    cold = overlays.srgb_to_linear(overlays.heat_color_srgb(0.0))
    np.testing.assert_allclose(soup[0, 3:], hot, rtol=1e-6)     # vertex 0 in both faces
    np.testing.assert_allclose(soup[3, 3:], hot, rtol=1e-6)
    np.testing.assert_allclose(soup[1, 3:], cold, rtol=1e-6)
    # the scale runs from the first stop to the last, monotonically brighter
    ramp = overlays.heat_color_srgb(np.linspace(0, 1, 50)).sum(axis=1)
    assert np.all(np.diff(ramp) > 0)


def test_one_glyph_per_face_and_one_per_vertex():
    scene = Scene()
    scene.objects = [Object(shape="sphere", radius=1.0, subdivisions=1, normals="average"),
                     Object(shape="box", normals="crease", translate=(3.0, 0.0, 0.0))]
    sphere, box = scene_meshes(scene)
    assert len(sphere.faces) == 80 and len(np.unique(sphere.faces)) == 42
    faces = overlays.face_normal_glyphs([sphere], 0.1)
    assert faces.shape == (2 * 80, 6)
    np.testing.assert_allclose(faces[0::2, :3], sphere.triangles.mean(axis=1), atol=1e-6)
    np.testing.assert_allclose(faces[1::2, :3] - faces[0::2, :3], 0.1 * sphere.face_normals,
                               atol=1e-6)
    glyphs = overlays.vertex_normal_glyphs([sphere], 0.1)
    assert glyphs.shape == (2 * 42, 6)                  # not 3 x 80 = 240 corner glyphs
    starts = glyphs[0::2, :3]
    assert len(np.unique(np.round(starts, 5), axis=0)) == 42    # one at each vertex
    np.testing.assert_allclose(np.linalg.norm(glyphs[1::2, :3] - starts, axis=1), 0.1,
                               rtol=1e-5)
    # a box with 30 degree creases: each corner has three normals (one per side), 8 x 3
    assert len(box.faces) == 12
    assert overlays.vertex_normal_glyphs([box], 0.1).shape == (2 * 24, 6)
    assert overlays.face_normal_glyphs([box], 0.1).shape == (2 * 12, 6)
    # flat shading's glyphs are the face glyphs (in the vertex glyphs' colour)
    np.testing.assert_array_equal(overlays.normal_glyphs([sphere], 0.1, "flat")[:, :3],
                                  faces[:, :3])


def test_the_shipped_fan_pyramid_shows_area_weighting_against_the_plain_average():
    scene = load_preset("normals")
    pyramid = next(m for m, o in zip(scene_meshes(scene), scene.objects, strict=True)
                   if o.shape == "mesh")
    v, f = pyramid.vertices, pyramid.faces
    areas = pyramid.areas
    assert areas.max() / areas.min() >= 7.9             # 1 side triangle vs 1/8 of a side
    area_vs_average = normal_mode_difference(v, f, "average", "area")
    assert area_vs_average.max() >= FAN_PYRAMID_MIN_DEGREES
    apex = int(np.argmax(v[:, 1]))
    assert area_vs_average[apex] == pytest.approx(area_vs_average.max())
    # at the apex the fan's eight thin triangles weigh as much as one side by area and by
    # angle: the two weighted rules agree there, the plain average leans to the fan
    assert normal_mode_difference(v, f, "area", "angle")[apex] < 1.0
    fan_side = pyramid.face_normals[0]
    avg = vertex_normals(v, f, "average")[apex]
    area = vertex_normals(v, f, "area")[apex]
    assert np.dot(avg, fan_side) > np.dot(area, fan_side) + 0.2
    # what the viewer draws: every object of the preset uses the plain average
    assert {o.normals for o in scene.objects} == {"average"}


def test_a_trimesh_icosphere_has_small_differences_only():
    """The contrast the step shows: on a near-regular mesh the rules agree within degrees."""
    sphere = trimesh.creation.icosphere(subdivisions=1)
    deg = normal_mode_difference(np.asarray(sphere.vertices), np.asarray(sphere.faces),
                                 "average", "area")
    assert deg.max() < 3.0
