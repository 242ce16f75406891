"""The interleaved per-corner vertex layout every shading program reads (one VBO per object).

One row per triangle corner, 15 float32: position, corner normal, face normal, centroid, uv,
terminator threshold (MeshData.corner_terminators).
Programs that do not use an attribute get it skipped as padding (the compiler drops unused
inputs, and moderngl refuses a format that names them), so one buffer serves every program.
"""

from __future__ import annotations

import moderngl
import numpy as np

VERTEX_FORMAT = "3f 3f 3f 3f 2f 1f"
VERTEX_ATTRIBUTES = ("in_position", "in_normal", "in_face_normal", "in_centroid", "in_uv",
                     "in_terminator")
VERTEX_FLOATS = 15  # float32 per corner


def triangle_soup(mesh) -> np.ndarray:
    """(3F, 15) float32 of a MeshData: position, corner normal, face normal, centroid, uv,
    terminator threshold per corner."""
    tri = mesh.triangles
    faces = len(mesh.faces)
    centroid = np.repeat(tri.mean(axis=1)[:, None, :], 3, axis=1)
    face_n = np.repeat(mesh.face_normals[:, None, :], 3, axis=1)
    uv = mesh.uvs[mesh.faces]
    soup = np.concatenate([tri, mesh.corner_normals, face_n, centroid, uv,
                           mesh.corner_terminators[..., None]], axis=2)
    return np.ascontiguousarray(soup.reshape(faces * 3, VERTEX_FLOATS), dtype=np.float32)


def padded_format(layout: list[str | None]) -> str:
    """Buffer format with unused attributes skipped as padding (``12x`` / ``8x``)."""
    parts = []
    for fmt, name in zip(VERTEX_FORMAT.split(), layout, strict=True):
        count = int(fmt[0])
        parts.append(fmt if name else f"{count * 4}x")
    return " ".join(parts)


def soup_vertex_array(ctx: moderngl.Context, program: moderngl.Program,
                      vbo: moderngl.Buffer) -> moderngl.VertexArray:
    """A VAO reading a :func:`triangle_soup` buffer with the attributes ``program`` uses."""
    layout = [a if a in program else None for a in VERTEX_ATTRIBUTES]
    return ctx.vertex_array(program, [(vbo, padded_format(layout), *[a for a in layout if a])])
