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


def terminator_threshold(fn: np.ndarray, cn: np.ndarray) -> float:
    """sin(delta): delta is the widest angle between a face's normal and its corner normals.

    A shading normal interpolated over a face stays within delta of the face normal, so on a
    face turned from the light (Ng.L <= 0) it has Ns.L <= sin(delta). Stencil shadow volumes
    put exactly those faces in shadow; the shadow pass fades the light over
    sin(delta) <= Ns.L <= 2 sin(delta) (:func:`shadelab.shading.reference.terminator_softening`)
    so the lit side meets the faces in the volume with no step. 0 for flat-shaded meshes.
    """
    if len(fn) == 0:
        return 0.0
    cosine = np.einsum("fk,fck->fc", fn, cn)
    worst = float(cosine.min())
    if worst <= 0.0:  # a corner normal turned past 90 degrees from its face: fade fully
        return 1.0
    sine = float(np.sqrt(max(0.0, 1.0 - worst * worst)))
    return sine if sine > 1e-6 else 0.0   # flat faces up to rounding (a rotated box: 1e-8)
