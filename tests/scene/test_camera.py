"""One matrix convention (column vectors, ``bFromA``): the raster's clip_from_world and the ray
tracer's primary rays agree on where every point lands."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shadelab.scene.camera import (
    clip_from_view,
    clip_from_world,
    gl_matrix,
    primary_rays,
    tan_half_fov_y,
    view_from_world,
)
from shadelab.scene.model import Camera

CAMERA = Camera(eye=(1.0, 2.0, 5.0), target=(0.2, -0.3, 0.0), up=(0.0, 1.0, 0.0), fov_y=45.0,
                near=0.1)


@pytest.mark.parametrize("far", [50.0, math.inf])
@pytest.mark.parametrize("w, h", [(40, 30), (24, 40)])   # landscape; portrait (fov widened)
def test_primary_ray_points_project_to_their_pixel_centres(far, w, h):
    origins, dirs = primary_rays(CAMERA, w, h)
    points = origins + 3.7 * dirs                       # (h, w, 3), 3.7 units along each ray
    homogeneous = np.concatenate([points, np.ones((h, w, 1))], axis=-1)
    clip = homogeneous @ clip_from_world(CAMERA, w / h, far).T   # column vectors: M @ p
    ndc = clip[..., :3] / clip[..., 3:]
    cols = (ndc[..., 0] + 1) / 2 * w - 0.5
    rows = (1 - ndc[..., 1]) / 2 * h - 0.5              # row 0 at the top
    np.testing.assert_allclose(cols, np.arange(w)[None, :].repeat(h, 0), atol=1e-9)
    np.testing.assert_allclose(rows, np.arange(h)[:, None].repeat(w, 1), atol=1e-9)
    assert np.all((ndc[..., 2] > -1) & (ndc[..., 2] < 1))


def test_view_from_world_puts_the_eye_at_the_origin_looking_down_minus_z():
    m = view_from_world(CAMERA)
    eye = m @ np.array([*CAMERA.eye, 1.0])
    target = m @ np.array([*CAMERA.target, 1.0])
    np.testing.assert_allclose(eye[:3], 0.0, atol=1e-12)
    distance = np.linalg.norm(np.subtract(CAMERA.target, CAMERA.eye))
    np.testing.assert_allclose(target[:3], [0.0, 0.0, -distance], atol=1e-12)
    # the composition is exactly the product, in that order
    np.testing.assert_allclose(clip_from_world(CAMERA, 1.5, 9.0),
                               clip_from_view(CAMERA, 1.5, 9.0) @ m)


def test_gl_matrix_is_column_major():
    m = np.arange(16, dtype=np.float64).reshape(4, 4)
    data = np.frombuffer(gl_matrix(m), dtype=np.float32)
    np.testing.assert_array_equal(data[:4], m[:, 0])    # first column first, as GLSL reads it


@pytest.mark.parametrize("fit", [1.0, 4.0 / 3.0, 16.0 / 9.0])
def test_a_narrow_image_keeps_the_fit_aspects_frame_side_to_side(fit):
    camera = Camera(eye=(0.0, 0.0, 5.0), target=(0.0, 0.0, 0.0), fov_y=40.0, fit_aspect=fit)
    t = math.tan(math.radians(40.0) / 2.0)
    for aspect in (fit, 2.0, 3.5):                       # as wide as the frame or wider: fov_y
        assert tan_half_fov_y(camera, aspect) == pytest.approx(t, rel=1e-15)
    for aspect in (0.5, 0.75, fit * 0.99):               # narrower: same horizontal half-width
        assert tan_half_fov_y(camera, aspect) * aspect == pytest.approx(t * fit, rel=1e-12)
        # the raster's projection says the same: x_ndc = 1 at the fit frame's edge
        edge = np.array([t * fit * 5.0, 0.0, 0.0, 1.0])
        clip = clip_from_world(camera, aspect, 50.0) @ edge
        assert clip[0] / clip[3] == pytest.approx(1.0, rel=1e-9)
    camera.fit_aspect = 0.0                               # 0: never widened
    assert tan_half_fov_y(camera, 0.3) == pytest.approx(t, rel=1e-15)
