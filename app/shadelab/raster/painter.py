"""List-priority rendering (the painter's algorithm): triangles sorted back to front by the
view depth of their centroids and drawn in that order with no depth test.

It fails where polygons overlap cyclically (A over B over C over A: no order is right) or
where a long triangle's centroid misrepresents its depth; ``presets/painter-cyclic.toml``
shows the first case beside the z-buffer. Shadow volumes need a depth buffer, so painter
frames are drawn without them.
"""

from __future__ import annotations

from dataclasses import dataclass

import moderngl
import numpy as np

from shadelab.gl.blend import restore_blend, set_blend
from shadelab.gl.vertex import VERTEX_FLOATS, soup_vertex_array, triangle_soup


@dataclass
class SortedSoup:
    """Triangles of several objects in one buffer, farthest first, in runs of one object."""

    soup: np.ndarray  # (3T, VERTEX_FLOATS) float32
    runs: list[tuple[int, int, int]]  # (object position in the list given, first tri, count)
    depth: np.ndarray  # (T,) view depth of each triangle's centroid, sorted descending


def view_forward(scene) -> np.ndarray:
    forward = np.asarray(scene.camera.target, float) - np.asarray(scene.camera.eye, float)
    return forward / np.linalg.norm(forward)


def sort_back_to_front(scene, meshes) -> SortedSoup:
    """Every triangle of ``meshes`` (MeshData) sorted by decreasing centroid view depth."""
    eye = np.asarray(scene.camera.eye, float)
    forward = view_forward(scene)
    soups, depths, owners = [], [], []
    for position, mesh in enumerate(meshes):
        soups.append(triangle_soup(mesh).reshape(-1, 3, VERTEX_FLOATS))
        depths.append((mesh.triangles.mean(axis=1) - eye) @ forward)
        owners.append(np.full(len(mesh.faces), position))
    if not soups:
        return SortedSoup(np.zeros((0, VERTEX_FLOATS), np.float32), [], np.zeros(0))
    depth = np.concatenate(depths)
    order = np.argsort(-depth, kind="stable")
    owner = np.concatenate(owners)[order]
    soup = np.concatenate(soups)[order].reshape(-1, VERTEX_FLOATS)
    starts = np.flatnonzero(np.diff(owner, prepend=-1))
    ends = np.append(starts[1:], len(owner))
    runs = [(int(owner[s]), int(s), int(e - s)) for s, e in zip(starts, ends, strict=True)]
    return SortedSoup(np.ascontiguousarray(soup), runs, depth[order])


def draw_sorted(renderer, scene, gpu_meshes, shading: str, sorted_soup: SortedSoup,
                before_run=None) -> None:
    """Draw a sorted soup run by run with each run's material (``before_run(material)`` sets
    any extra state, e.g. the blend factors of transparency)."""
    if not sorted_soup.runs:
        return
    ctx = renderer.ctx
    vbo = ctx.buffer(sorted_soup.soup.tobytes())
    vaos: dict[str, moderngl.VertexArray] = {}
    try:
        for position, first, count in sorted_soup.runs:
            name = gpu_meshes[position].mesh.material
            program_name = renderer.use_material(scene, name, shading)
            if program_name not in vaos:
                vaos[program_name] = soup_vertex_array(ctx, renderer.programs[program_name],
                                                       vbo)
            if before_run is not None:
                before_run(scene.materials[name])
            vaos[program_name].render(moderngl.TRIANGLES, vertices=3 * count, first=3 * first)
    finally:
        for vao in vaos.values():
            vao.release()
        vbo.release()


def draw_painter(renderer, scene, gpu_meshes, shading: str, view) -> None:
    """The whole frame by list priority: no depth test, farthest triangles first
    (transparent materials blended as in :mod:`shadelab.raster.transparency`)."""
    ctx = renderer.ctx
    ctx.enable_only(moderngl.NOTHING)
    soup = sort_back_to_front(scene, [g.mesh for g in gpu_meshes])
    try:  # back to front is also the order transparency needs: blend those runs
        draw_sorted(renderer, scene, gpu_meshes, shading, soup,
                    lambda material: set_blend(ctx, material))
    finally:
        restore_blend(ctx)
        ctx.enable_only(moderngl.DEPTH_TEST)
