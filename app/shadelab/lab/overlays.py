"""Overlay geometry as colored line segments: wireframe, normal glyphs, probe arrows.

Pure numpy: each function returns a (2S, 6) float32 array, position and linear RGB color per
segment end, drawn by ``shaders/lines.*``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from shadelab.geometry.mesh import MeshData, scene_bounds
from shadelab.geometry.normals import normal_mode_difference

WIRE_COLOR = (0.05, 0.05, 0.05)
NORMAL_COLOR = (0.2, 0.6, 1.0)      # vertex normals
FACE_NORMAL_COLOR = (0.3, 1.0, 0.35)  # face normals (no heat-map colour is green)
ARROW_COLORS = {"N": (1.0, 1.0, 1.0), "V": (0.2, 0.9, 1.0), "L": (1.0, 0.85, 0.1),
                "R": (1.0, 0.3, 0.9), "H": (1.0, 0.3, 0.9)}


def _segments(starts: np.ndarray, ends: np.ndarray, color) -> np.ndarray:
    n = len(starts)
    out = np.empty((n, 2, 6), np.float32)
    out[:, 0, :3], out[:, 1, :3] = starts, ends
    out[:, :, 3:] = color
    return out.reshape(-1, 6)


def scene_diagonal(meshes: list[MeshData]) -> float:
    lo, hi = scene_bounds(meshes)
    return float(np.linalg.norm(hi - lo))


def wireframe(meshes: list[MeshData], color=WIRE_COLOR) -> np.ndarray:
    """Every triangle edge once per triangle (shared edges twice: cheap and simple)."""
    parts = []
    for mesh in meshes:
        tri = mesh.triangles
        starts = tri.reshape(-1, 3)
        ends = tri[:, [1, 2, 0]].reshape(-1, 3)
        parts.append(_segments(starts, ends, color))
    return np.concatenate(parts) if parts else np.zeros((0, 6), np.float32)


def face_normal_glyphs(meshes: list[MeshData], length: float,
                       color=FACE_NORMAL_COLOR) -> np.ndarray:
    """One glyph per face: N = (V2 - V1) x (V3 - V1), normalized, from the face's centroid
    (zero-area faces, whose normal is zero, are left out)."""
    parts = []
    for mesh in meshes:
        real = np.linalg.norm(mesh.face_normals, axis=1) > 0.5
        starts = mesh.triangles[real].mean(axis=1)
        parts.append(_segments(starts, starts + length * mesh.face_normals[real], color))
    return np.concatenate(parts) if parts else np.zeros((0, 6), np.float32)


def vertex_normal_table(mesh: MeshData) -> tuple[np.ndarray, np.ndarray]:
    """(P, 3) positions and (P, 3) unit normals: one row per distinct (vertex, normal) pair of
    the mesh's corners. A smooth vertex shared by six faces is one row (not six parallel
    corner glyphs); a vertex on a crease keeps one row per side of it."""
    if len(mesh.faces) == 0:
        return np.zeros((0, 3)), np.zeros((0, 3))
    vertex = mesh.faces.reshape(-1)
    normals = mesh.corner_normals.reshape(-1, 3)
    keys = np.concatenate([vertex[:, None].astype(np.float64),
                           np.round(normals * 1e6)], axis=1)
    _, first = np.unique(keys, axis=0, return_index=True)
    first = np.sort(first)
    return mesh.vertices[vertex[first]], normals[first]


def vertex_normal_glyphs(meshes: list[MeshData], length: float,
                         color=NORMAL_COLOR) -> np.ndarray:
    """One glyph per vertex (per side of a crease), from the vertex, its normal by the
    object's normals mode (:func:`vertex_normal_table`)."""
    parts = []
    for mesh in meshes:
        starts, dirs = vertex_normal_table(mesh)
        parts.append(_segments(starts, starts + length * dirs, color))
    return np.concatenate(parts) if parts else np.zeros((0, 6), np.float32)


def normal_glyphs(meshes: list[MeshData], length: float, shading: str,
                  color=NORMAL_COLOR) -> np.ndarray:
    """The normals the shading mode uses: face normals at centroids (flat), else one per
    vertex (:func:`vertex_normal_glyphs`)."""
    if shading == "flat":
        return face_normal_glyphs(meshes, length, color)
    return vertex_normal_glyphs(meshes, length, color)


# ---------------------------------------------------------------- normal-mode heat map

#: The heat map's colour scale, sRGB stops from 0 (dark blue) to full scale (pale yellow).
HEAT_STOPS = np.array([[0.05, 0.05, 0.35], [0.45, 0.1, 0.6], [0.85, 0.25, 0.35],
                       [0.98, 0.6, 0.1], [1.0, 0.95, 0.55]])


def heat_color_srgb(t) -> np.ndarray:
    """(..., 3) sRGB in [0, 1] of the heat scale at ``t`` in [0, 1] (clamped)."""
    t = np.clip(np.asarray(t, dtype=np.float64), 0.0, 1.0) * (len(HEAT_STOPS) - 1)
    i = np.minimum(np.floor(t).astype(int), len(HEAT_STOPS) - 2)
    f = (t - i)[..., None]
    return HEAT_STOPS[i] * (1.0 - f) + HEAT_STOPS[i + 1] * f


def srgb_to_linear(c: np.ndarray) -> np.ndarray:
    c = np.asarray(c, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def heat_scale_max(degrees: float) -> float:
    """The legend's full scale: the largest angle rounded up to 5 degrees (at least 5)."""
    return float(max(5.0, 5.0 * np.ceil(degrees / 5.0 - 1e-9)))


def normal_difference(meshes: list[MeshData], mode_a: str, mode_b: str) -> list[np.ndarray]:
    """Per mesh, (V,) the angle in degrees between its vertex normals by rule ``mode_a`` and
    by rule ``mode_b`` (:func:`shadelab.geometry.normals.normal_mode_difference`)."""
    return [normal_mode_difference(m.vertices, m.faces, mode_a, mode_b) for m in meshes]


def normal_difference_soup(meshes: list[MeshData], degrees: list[np.ndarray],
                           full_scale: float) -> np.ndarray:
    """(3F, 6) float32 triangles coloured by the angle at their corners (linear RGB of
    :func:`heat_color_srgb` at angle / ``full_scale``), drawn over the scene."""
    parts = []
    for mesh, deg in zip(meshes, degrees, strict=True):
        if len(mesh.faces) == 0:
            continue
        color = srgb_to_linear(heat_color_srgb(deg / full_scale))
        parts.append(np.concatenate([mesh.triangles.reshape(-1, 3),
                                     color[mesh.faces].reshape(-1, 3)], axis=1))
    if not parts:
        return np.zeros((0, 6), np.float32)
    return np.ascontiguousarray(np.concatenate(parts), dtype=np.float32)


def arrow(start: np.ndarray, direction: np.ndarray, length: float, color) -> np.ndarray:
    """A shaft plus a four-line head (readable from any side)."""
    d = np.asarray(direction, dtype=np.float64)
    d = d / max(np.linalg.norm(d), 1e-12)
    tip = start + length * d
    side = np.cross(d, [0.0, 1.0, 0.0] if abs(d[1]) < 0.9 else [1.0, 0.0, 0.0])
    side /= np.linalg.norm(side)
    other = np.cross(d, side)
    head = 0.15 * length
    back = tip - head * d
    starts = [start] + [tip] * 4
    ends = [tip, back + 0.5 * head * side, back - 0.5 * head * side,
            back + 0.5 * head * other, back - 0.5 * head * other]
    return _segments(np.array(starts), np.array(ends), color)


def probe_arrows(result, length: float) -> np.ndarray:
    """N, V, and per light L_i and R_i (or H_i) at the probed point."""
    p = result.point
    parts = [arrow(p, result.normal, length, ARROW_COLORS["N"]),
             arrow(p, result.to_eye, length, ARROW_COLORS["V"])]
    for i, term in enumerate(result.terms.lights):
        parts.append(arrow(p, term.to_light, length, ARROW_COLORS["L"]))
        parts.append(arrow(p, result.reflected(i), length * 0.8, ARROW_COLORS["R"]))
    return np.concatenate(parts)


ARROW_VIEW_FRACTION = 0.15  # a probe arrow's length: share of the view's height at the point
ARROW_MARGIN = 0.1          # its head stays this share of the half-frame inside the edges


@dataclass
class ArrowSpec:
    """One probe arrow: ``name`` (N, V, L, R or H; with the light's number when there are
    several lights) drawn from ``start`` along the unit ``direction``, ``length`` long."""

    name: str
    start: np.ndarray
    direction: np.ndarray
    length: float
    color: tuple

    @property
    def tip(self) -> np.ndarray:
        return self.start + self.length * self.direction


def _inside(clip_from_world: np.ndarray, point: np.ndarray, limit: float) -> bool:
    p = clip_from_world @ np.append(point, 1.0)
    return bool(p[3] > 1e-9 and abs(p[0]) <= limit * p[3] and abs(p[1]) <= limit * p[3])


def probe_arrow_specs(result, camera, aspect: float, fraction: float = ARROW_VIEW_FRACTION,
                      margin: float = ARROW_MARGIN) -> list[ArrowSpec]:
    """N, V, and per light L_i and R_i (or H_i) at the probed point, each ``fraction`` of the
    view's height long at the point's depth (the same on screen however large the scene),
    shortened where needed so that its head stays inside the frame (``margin`` of the
    half-frame from the edges) at the viewport's ``aspect``."""
    from shadelab.scene.camera import camera_basis, clip_from_world, tan_half_fov_y

    point = np.asarray(result.point, dtype=np.float64)
    forward, _, _ = camera_basis(camera)
    depth = max(float(np.dot(point - np.asarray(camera.eye, dtype=np.float64), forward)),
                camera.near)
    length = fraction * 2.0 * depth * tan_half_fov_y(camera, aspect)
    clip = clip_from_world(camera, aspect, far=1e3 * depth + 1.0)
    limit = 1.0 - margin
    several = len(result.terms.lights) > 1
    reflected = "H" if result.specular == "blinn" else "R"
    wanted = [("N", result.normal, 1.0), ("V", result.to_eye, 1.0)]
    for i, term in enumerate(result.terms.lights):
        suffix = str(i + 1) if several else ""
        wanted.append(("L" + suffix, term.to_light, 1.0))
        wanted.append((reflected + suffix, result.reflected(i), 0.8))
    specs = []
    for name, direction, scale in wanted:
        d = np.asarray(direction, dtype=np.float64)
        d = d / max(np.linalg.norm(d), 1e-12)
        full = length * scale
        # a point in the margin itself: its arrows stay inside the frame's edge
        here = limit if _inside(clip, point, limit) else 1.0
        if _inside(clip, point, here) and not _inside(clip, point + full * d, here):
            lo, hi = 0.0, full            # the screen image of a segment leaves a box once
            for _ in range(30):
                mid = 0.5 * (lo + hi)
                lo, hi = (mid, hi) if _inside(clip, point + mid * d, here) else (lo, mid)
            full = lo
        specs.append(ArrowSpec(name, point, d, full, ARROW_COLORS[name[0]]))
    return specs


def arrow_lines(specs: list[ArrowSpec]) -> np.ndarray:
    """The probe arrows as segments (a shaft and a four-line head each)."""
    if not specs:
        return np.zeros((0, 6), np.float32)
    return np.concatenate([arrow(s.start, s.direction, s.length, s.color) for s in specs])


RAY_COLORS = {"primary": (1.0, 1.0, 1.0), "shadow": (1.0, 0.85, 0.1), "blocked": (1.0, 0.2, 0.2),
              "reflected": (0.2, 0.9, 1.0), "refracted": (0.3, 1.0, 0.3)}


def ray_tree_lines(root, miss_length: float) -> np.ndarray:
    """Every ray of a ray tree as a segment, colored by kind (blocked shadow rays red)."""
    parts = []
    for _, node in root.flatten():
        end = node.end if node.end is not None else node.origin + miss_length * node.direction
        kind = "blocked" if node.kind == "shadow" and node.shadow < 1.0 else node.kind
        parts.append(_segments(np.array([node.origin]), np.array([end]), RAY_COLORS[kind]))
    return np.concatenate(parts) if parts else np.zeros((0, 6), np.float32)


def radiosity_soup(meshes: list) -> np.ndarray:
    """(3F, 6) float32 position and radiance per corner of radiosity display meshes."""
    parts = [np.concatenate([np.asarray(v)[f].reshape(-1, 3), np.asarray(c)[f].reshape(-1, 3)],
                            axis=1) for v, f, c in meshes if len(f)]
    if not parts:
        return np.zeros((0, 6), np.float32)
    return np.ascontiguousarray(np.concatenate(parts), dtype=np.float32)
