"""Quadrature points on patches and the hemicube's delta form factors: the pure numpy pieces
that the form-factor engine (:mod:`shadelab.radiosity.formfactors`) and the GPU hemicube
(:mod:`shadelab.raster.hemicube`) share.
"""

from __future__ import annotations

import numpy as np

GAUSS_ORDER = 2  # receiver quadrature: 2x2 Gauss-Legendre points per patch (3: 0.01 % on
#                  the unit squares, 2: 0.7 %, at less than half the cost)
SOURCE_GRID = 4  # source sample points per edge (4x4) that visibility rays aim at


# ---------------------------------------------------------------------- sample points
def bilinear_samples(polygons: np.ndarray, t: np.ndarray, w: np.ndarray):
    """Points (N, K, 3) and area weights (N, K) summing to 1 on each (N, 4, 3) polygon.

    ``t``, ``w`` are 1-D rule nodes in [0, 1] and weights; the bilinear Jacobian makes the
    rule exact for area and handles triangles (a repeated corner) too.
    """
    u, v = np.meshgrid(t, t, indexing="ij")
    u, v = u.reshape(-1), v.reshape(-1)
    weight = np.outer(w, w).reshape(-1)
    p0, p1, p2, p3 = (polygons[:, k, None, :] for k in range(4))
    uu, vv = u[None, :, None], v[None, :, None]
    points = (1 - uu) * (1 - vv) * p0 + uu * (1 - vv) * p1 + uu * vv * p2 + (1 - uu) * vv * p3
    du = (1 - vv) * (p1 - p0) + vv * (p2 - p3)
    dv = (1 - uu) * (p3 - p0) + uu * (p2 - p1)
    jac = np.linalg.norm(np.cross(du, dv), axis=-1) * weight[None, :]
    return points, jac / np.maximum(jac.sum(axis=1, keepdims=True), 1e-300)


def receiver_samples(polygons: np.ndarray, order: int = GAUSS_ORDER):
    g, w = np.polynomial.legendre.leggauss(order)
    return bilinear_samples(polygons, (g + 1.0) / 2.0, w / 2.0)


def source_samples(polygons: np.ndarray, grid: int = SOURCE_GRID):
    t = (np.arange(grid) + 0.5) / grid
    return bilinear_samples(polygons, t, np.full(grid, 1.0 / grid))


def hemicube_delta_factors(resolution: int) -> tuple[np.ndarray, np.ndarray]:
    """Delta form factors of a hemicube: top (res, res) and one side (res // 2, res).

    Top face at z = 1, cells of side 2 / res: dF = dA / (pi (x^2 + y^2 + 1)^2). Side face
    x = 1, upper half z in (0, 1): dF = z dA / (pi (y^2 + z^2 + 1)^2). Side rows run from
    z near 1 (row 0) down to the horizon. Top + 4 sides sum to 1 (up to discretization).
    """
    res = int(resolution)
    c = -1.0 + (np.arange(res) + 0.5) * (2.0 / res)
    da = (2.0 / res) ** 2
    x, y = np.meshgrid(c, c, indexing="xy")
    top = da / (np.pi * (x * x + y * y + 1.0) ** 2)
    z = c[res // 2:][::-1]
    yy, zz = np.meshgrid(c, z, indexing="xy")
    side = zz * da / (np.pi * (yy * yy + zz * zz + 1.0) ** 2)
    return top, side
