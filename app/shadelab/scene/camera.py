"""Camera math shared by every renderer, so raster, ray-traced and radiosity images align.

One matrix convention everywhere (pbrt's): column vectors, ``p_b = b_from_a @ p_a``, and every
matrix is named ``bFromA`` (``clip_from_world = clip_from_view @ view_from_world``). pyrr builds
row-vector matrices; they are transposed once here, and :func:`gl_matrix` transposes once more
at the GL boundary into the column-major bytes GLSL expects.
"""

from __future__ import annotations

import math

import numpy as np
from pyrr import Matrix44

from shadelab.scene.model import Camera


def camera_basis(camera: Camera) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit forward, right and up vectors of the camera, world space."""
    eye = np.asarray(camera.eye, dtype=np.float64)
    forward = np.asarray(camera.target, dtype=np.float64) - eye
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, np.asarray(camera.up, dtype=np.float64))
    if np.linalg.norm(right) < 1e-12:  # up parallel to the view: pick any perpendicular
        right = np.cross(forward, [1.0, 0.0, 0.0] if abs(forward[0]) < 0.9 else [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    return forward, right, up


def tan_half_fov_y(camera: Camera, aspect: float) -> float:
    """tan(half the vertical field of view) of an image ``aspect`` = width / height wide.

    It is ``tan(fov_y / 2)``, widened when the image is narrower than ``camera.fit_aspect``
    (a portrait viewport, a narrow presenter column) so that the frame ``fov_y`` shows at that
    aspect stays in view left to right (Mitsuba's ``fov_axis = "smaller"`` when it is 1). The
    one source of the projection's scale: the raster, both ray tracers, the probe, gizmos and
    camera drags read it, so their images stay aligned at every aspect."""
    t = math.tan(math.radians(camera.fov_y) / 2.0)
    fit = float(camera.fit_aspect)
    if fit > 0.0 and 0.0 < aspect < fit:
        t *= fit / aspect
    return t


def view_from_world(camera: Camera) -> np.ndarray:
    """4x4 float64 ``view_from_world`` (column vectors): the eye at the origin looking down -z."""
    forward, _, up = camera_basis(camera)
    eye = np.asarray(camera.eye, dtype=np.float64)
    return np.asarray(Matrix44.look_at(eye, eye + forward, up), dtype=np.float64).T


def clip_from_view(camera: Camera, aspect: float, far: float) -> np.ndarray:
    """4x4 float64 ``clip_from_view`` (column vectors): a perspective with the camera's vertical
    fov (:func:`tan_half_fov_y`); ``far`` may be inf (the infinite far plane of Everitt &
    Kilgard 2002)."""
    tan_half = tan_half_fov_y(camera, aspect)
    if math.isinf(far):
        f = 1.0 / tan_half
        near = camera.near
        return np.array([[f / aspect, 0, 0, 0],
                         [0, f, 0, 0],
                         [0, 0, -1.0, -2.0 * near],
                         [0, 0, -1.0, 0]], dtype=np.float64)
    fov_y = math.degrees(2.0 * math.atan(tan_half))
    return np.asarray(Matrix44.perspective_projection(fov_y, aspect, camera.near, far),
                      dtype=np.float64).T


def clip_from_world(camera: Camera, aspect: float, far: float) -> np.ndarray:
    """4x4 float64 ``clip_from_world = clip_from_view @ view_from_world`` (column vectors)."""
    return clip_from_view(camera, aspect, far) @ view_from_world(camera)


def far_plane(camera: Camera, bounds: np.ndarray) -> float:
    """A far plane just behind the farthest corner of the scene's (2, 3) bounds."""
    corners = np.array([[bounds[i][0], bounds[j][1], bounds[k][2]]
                        for i in (0, 1) for j in (0, 1) for k in (0, 1)])
    distance = np.linalg.norm(corners - np.asarray(camera.eye), axis=1).max()
    return float(max(distance * 1.5, camera.near * 10.0))


def gl_matrix(matrix: np.ndarray) -> bytes:
    """Bytes of a column-vector ``bFromA`` matrix as a GLSL ``mat4`` uniform (float32,
    column-major: the one transpose at the GL boundary)."""
    return np.ascontiguousarray(np.asarray(matrix).T, dtype=np.float32).tobytes()


def primary_rays(camera: Camera, width: int, height: int,
                 jitter: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Origins and unit directions (height, width, 3) through pixel centres, row 0 at the top.

    ``jitter`` (height, width, 2) in [0, 1) moves the sample inside the pixel (stratified
    anti-aliasing); without it the ray passes through the centre, as the rasterizer samples.
    """
    forward, right, up = camera_basis(camera)
    aspect = width / height
    tan_half = tan_half_fov_y(camera, aspect)
    offset = np.full((height, width, 2), 0.5) if jitter is None else jitter
    cols = (np.arange(width)[None, :] + offset[..., 0]) / width
    rows = (np.arange(height)[:, None] + offset[..., 1]) / height
    x = (2.0 * cols - 1.0) * tan_half * aspect
    y = (1.0 - 2.0 * rows) * tan_half
    directions = forward + x[..., None] * right + y[..., None] * up
    directions /= np.linalg.norm(directions, axis=-1, keepdims=True)
    origins = np.broadcast_to(np.asarray(camera.eye, dtype=np.float64), directions.shape).copy()
    return origins, directions
