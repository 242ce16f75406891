"""Overlay geometry as colored line segments: wireframe, normal glyphs, probe arrows.

Pure numpy: each function returns a (2S, 6) float32 array, position and linear RGB color per
segment end, drawn by ``shaders/lines.*``.
"""

from __future__ import annotations

import numpy as np

from shadelab.geometry.mesh import MeshData, scene_bounds

WIRE_COLOR = (0.05, 0.05, 0.05)
NORMAL_COLOR = (0.2, 0.6, 1.0)
ARROW_COLORS = {"N": (1.0, 1.0, 1.0), "V": (0.2, 0.9, 1.0), "L": (1.0, 0.85, 0.1),
                "R": (1.0, 0.3, 0.9)}


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


def normal_glyphs(meshes: list[MeshData], length: float, shading: str,
                  color=NORMAL_COLOR) -> np.ndarray:
    """The normals the shading mode uses: face normals at centroids (flat), else per corner."""
    parts = []
    for mesh in meshes:
        tri = mesh.triangles
        if shading == "flat":
            starts, dirs = tri.mean(axis=1), mesh.face_normals
        else:
            # Pull corner glyphs a little into the triangle so split (crease) normals separate.
            starts = (tri * 0.9 + tri.mean(axis=1, keepdims=True) * 0.1).reshape(-1, 3)
            dirs = mesh.corner_normals.reshape(-1, 3)
        parts.append(_segments(starts, starts + length * dirs, color))
    return np.concatenate(parts) if parts else np.zeros((0, 6), np.float32)


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
