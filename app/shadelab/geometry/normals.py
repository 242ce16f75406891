"""Normals as the lecture defines them: face normals by the right-hand rule, vertex normals by
averaging (plain, area-weighted, angle-weighted), and per-corner normals split at a crease angle.

Shapes: ``vertices (V, 3) float``, ``faces (F, 3) int`` counter-clockwise seen from the front.
"""

from __future__ import annotations

import numpy as np

_EPS = 1e-20


def _unit(v: np.ndarray) -> np.ndarray:
    length = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.where(length > _EPS, v / np.maximum(length, _EPS), 0.0)


def face_cross(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Unnormalized face normals (F, 3): N = (P2 - P1) x (P3 - P1); |N| = 2 x area.

    With the corners counter-clockwise seen from the front, the right-hand rule makes N
    point out of the front face.
    """
    p = vertices[faces]
    return np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])


def face_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Unit face normals (F, 3); a degenerate (zero-area) face gets the zero vector."""
    return _unit(face_cross(vertices, faces))


def face_areas(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    return 0.5 * np.linalg.norm(face_cross(vertices, faces), axis=-1)


def corner_angles(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Interior angle (F, 3) of each triangle at each of its corners, radians."""
    p = vertices[faces]
    out = np.empty(faces.shape)
    for k in range(3):
        a = _unit(p[:, (k + 1) % 3] - p[:, k])
        b = _unit(p[:, (k + 2) % 3] - p[:, k])
        out[:, k] = np.arccos(np.clip(np.sum(a * b, axis=-1), -1.0, 1.0))
    return out


def _corner_weights(vertices: np.ndarray, faces: np.ndarray, weighting: str) -> np.ndarray:
    if weighting == "average":
        return np.ones(faces.shape)
    if weighting == "area":
        return np.repeat(face_areas(vertices, faces)[:, None], 3, axis=1)
    if weighting == "angle":
        return corner_angles(vertices, faces)
    raise ValueError(f"unknown weighting {weighting!r}")


def vertex_normals(vertices: np.ndarray, faces: np.ndarray, weighting: str = "angle") -> np.ndarray:
    """Unit vertex normals (V, 3): the normalized weighted sum of the adjacent face normals.

    Notes
    -----
    N_v = sum_i w_i N_i / |sum_i w_i N_i| with w_i = 1 (average), the face area (area) or the
    face's interior angle at the vertex (angle). A vertex whose sum vanishes gets zero.
    """
    fn = face_normals(vertices, faces)
    weights = _corner_weights(vertices, faces, weighting)
    acc = np.zeros((len(vertices), 3))
    for k in range(3):
        np.add.at(acc, faces[:, k], fn * weights[:, k:k + 1])
    return _unit(acc)


def crease_corner_normals(vertices: np.ndarray, faces: np.ndarray,
                          crease_angle_deg: float, progress=None) -> np.ndarray:
    """Per-corner normals (F, 3, 3): angle-weighted average over the faces around the vertex
    whose normals lie within ``crease_angle_deg`` of this face's normal.

    A cube (crease 30 degrees) keeps its sharp edges; a sphere stays smooth. ``progress``,
    when given, is called with a count of triangles (corners / 3) as the work goes on.
    """
    fn = face_normals(vertices, faces)
    weights = corner_angles(vertices, faces)
    cos_limit = np.cos(np.radians(crease_angle_deg)) - 1e-9
    # Group corners by vertex: corner c = 3 f + k touches vertex faces[f, k].
    corner_vertex = faces.reshape(-1)
    order = np.argsort(corner_vertex, kind="stable")
    sorted_v = corner_vertex[order]
    starts = np.flatnonzero(np.r_[True, sorted_v[1:] != sorted_v[:-1]])
    ends = np.r_[starts[1:], len(sorted_v)]
    corner_face = order // 3
    wn = fn[corner_face] * weights.reshape(-1)[order][:, None]
    out = np.zeros((len(corner_vertex), 3))
    step = max(len(starts) // 100, 1)
    reported = 0
    for i, (s, e) in enumerate(zip(starts, ends, strict=True)):
        group = order[s:e]
        normals_here = fn[group // 3]                     # (k, 3) face normal of each corner
        close = normals_here @ normals_here.T >= cos_limit  # (k, k) faces within the crease
        out[group] = close.astype(float) @ wn[s:e]
        if progress is not None and (i + 1) % step == 0:
            progress(e // 3 - reported)
            reported = e // 3
    if progress is not None and len(faces) > reported:
        progress(len(faces) - reported)
    out = _unit(out).reshape(faces.shape + (3,))
    return _fallback(out, fn)


def _fallback(corner: np.ndarray, fn: np.ndarray) -> np.ndarray:
    """Replace zero-length corner normals by the face normal (degenerate neighbourhoods)."""
    bad = np.linalg.norm(corner, axis=-1) < 0.5
    return np.where(bad[..., None], fn[:, None, :], corner)


def corner_normals(vertices: np.ndarray, faces: np.ndarray, mode: str,
                   crease_angle_deg: float = 30.0, progress=None) -> np.ndarray:
    """Per-corner normals (F, 3, 3) for a normals mode of
    :data:`shadelab.scene.model.NORMALS_MODES`; ``progress(triangles)`` as in
    :func:`crease_corner_normals` (the other modes are one vectorized step)."""
    fn = face_normals(vertices, faces)
    if mode == "flat":
        out = np.repeat(fn[:, None, :], 3, axis=1)
    elif mode == "crease":
        return crease_corner_normals(vertices, faces, crease_angle_deg, progress)
    else:
        vn = vertex_normals(vertices, faces, mode)
        out = _fallback(vn[faces], fn)
    if progress is not None:
        progress(len(faces))
    return out


def corner_sines(fn: np.ndarray, cn: np.ndarray) -> np.ndarray:
    """(F, 3) sin of the angle between each corner normal and its face's normal: the
    bound at that corner for that face alone (:func:`vertex_terminators` shares it).

    A shading normal interpolated over a face from its corners has Ns.L <= sum_k b_k s_k /
    |sum_k b_k N_k| on a face turned from the light (Ng.L <= 0), since N_k.L <= s_k there
    (:func:`threshold_at`). A corner normal more than 90 degrees from its face (a fold or a
    sliver on a real mesh) bounds nothing below 1; it is left out of the fade (s = 0)
    rather than darken its faces' lit side (:func:`flipped_corners` counts them).
    """
    sine = np.linalg.norm(np.cross(cn, fn[:, None, :]), axis=-1)
    return np.where(np.einsum("fk,fck->fc", fn, cn) > 0.0, sine, 0.0)


def vertex_terminators(vertices: np.ndarray, faces: np.ndarray, fn: np.ndarray,
                       cn: np.ndarray) -> np.ndarray:
    """(F, 3) the terminator threshold t_v at each corner: the largest :func:`corner_sines`
    over the corners that share its position and its normal (the faces the shading normal is
    continuous over). Both faces of a silhouette edge then interpolate the same t along it,
    so the fade is 0 there on the lit face as on the face in its own shadow volume: no step.
    """
    sines = corner_sines(fn, cn)
    if len(faces) == 0:
        return sines
    keys = np.concatenate([vertices[faces].reshape(-1, 3), cn.reshape(-1, 3)], axis=1)
    _, group = np.unique(keys, axis=0, return_inverse=True)
    group = group.reshape(-1)
    most = np.zeros(group.max() + 1)
    np.maximum.at(most, group, sines.reshape(-1))
    return most[group].reshape(faces.shape)


def flipped_corners(fn: np.ndarray, cn: np.ndarray) -> int:
    """How many corner normals lean more than 90 degrees from their face (degenerate faces,
    whose normal is zero, not counted)."""
    if len(fn) == 0:
        return 0
    real = np.linalg.norm(fn, axis=-1) > 0.5
    return int(np.count_nonzero((np.einsum("fk,fck->fc", fn, cn) <= 0.0) & real[:, None]))


def threshold_at(sines: np.ndarray, cn: np.ndarray, bary: np.ndarray) -> np.ndarray:
    """The terminator threshold (...) at points inside faces: sum_k b_k s_k / |sum_k b_k N_k|.

    ``sines`` (..., 3) and ``cn`` (..., 3, 3) of each point's face, ``bary`` (..., 3). The
    Phong fragment shader interpolates s_k and N_k the same way (phong.vert / phong.frag);
    Gouraud shades at the corners, where it is s_k.
    """
    m = np.einsum("...c,...ck->...k", bary, cn)
    return np.einsum("...c,...c->...", bary, sines) / np.maximum(np.linalg.norm(m, axis=-1),
                                                                   1e-12)


def terminator_threshold(fn: np.ndarray, cn: np.ndarray) -> float:
    """sin(delta): delta is the widest angle between a face's normal and its corner normals
    (corner normals more than 90 degrees from their face left out, as in
    :func:`corner_sines`): the largest of the mesh's corner thresholds.

    A shading normal interpolated over a face stays within delta of the face normal, so on a
    face turned from the light (Ng.L <= 0) it has Ns.L <= sin(delta). Stencil shadow volumes
    put exactly those faces in shadow; the shadow pass fades the light over
    t <= Ns.L <= 2 t (:func:`shadelab.shading.reference.terminator_softening`) with t the
    point's own threshold (:func:`threshold_at`), at most about this, so the lit side meets
    the faces in the volume with no step. 0 for flat-shaded meshes.
    """
    if len(fn) == 0:
        return 0.0
    sine = float(corner_sines(fn, cn).max())
    return sine if sine > 1e-6 else 0.0   # flat faces up to rounding (a rotated box: 1e-8)


VERTEX_MODES = ("average", "area", "angle")   # the vertex-normal rules a heat map compares


def angle_between_degrees(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(...) the angle between unit vectors ``a`` and ``b`` (..., 3), degrees (atan2 of the
    cross and dot products: accurate near 0 and 180 degrees, where arccos is not)."""
    cross = np.linalg.norm(np.cross(a, b), axis=-1)
    return np.degrees(np.arctan2(cross, np.sum(a * b, axis=-1)))


def normal_mode_difference(vertices: np.ndarray, faces: np.ndarray, mode_a: str,
                           mode_b: str) -> np.ndarray:
    """(V,) the angle in degrees between each vertex's normal by rule ``mode_a`` and by rule
    ``mode_b`` (two of :data:`VERTEX_MODES`): where plain averaging, area weighting and angle
    weighting disagree (a vertex whose faces differ much in size or corner angle)."""
    for mode in (mode_a, mode_b):
        if mode not in VERTEX_MODES:
            raise ValueError(f"normal mode {mode!r}: one of {', '.join(VERTEX_MODES)}")
    return angle_between_degrees(vertex_normals(vertices, faces, mode_a),
                                 vertex_normals(vertices, faces, mode_b))
