"""The GL image of a radiosity solution: per-vertex radiance, Gouraud-interpolated by the
rasterizer (shaders/radiosity.vert/.frag) into a :class:`RenderTarget`, with the camera
matrices of the raster renderer (:func:`shadelab.raster.renderer.make_view`), so the image aligns
pixel for pixel with the raster and ray-traced images.
"""

from __future__ import annotations

import moderngl
import numpy as np

from shadelab.geometry.mesh import scene_meshes
from shadelab.gl.context import headless_context
from shadelab.gl.programs import load_program
from shadelab.gl.target import RenderTarget
from shadelab.raster.hemicube import rebind
from shadelab.raster.renderer import make_view
from shadelab.scene.camera import gl_matrix
from shadelab.scene.model import Scene

_PROGRAMS: dict[int, moderngl.Program] = {}


def triangle_soup(meshes: list) -> np.ndarray:
    """(3F, 6) float32: position and radiance per corner of every display triangle."""
    parts = [np.concatenate([v[f].reshape(-1, 3), c[f].reshape(-1, 3)], axis=1)
             for v, f, c in meshes if len(f)]
    return np.ascontiguousarray(np.concatenate(parts), dtype=np.float32)


def render_meshes(scene: Scene, meshes: list, size: tuple[int, int],
                  ctx: moderngl.Context | None = None) -> np.ndarray:
    """Linear radiance (H, W, 3) float32 of display meshes from the scene camera, row 0 on top."""
    ctx = ctx or headless_context()
    program = _PROGRAMS.get(id(ctx))
    if program is None:
        program = _PROGRAMS[id(ctx)] = load_program(ctx, "radiosity")
    view = make_view(scene, size, scene_meshes(scene))
    target = RenderTarget(ctx, size)
    vbo = ctx.buffer(triangle_soup(meshes).tobytes())
    vao = ctx.vertex_array(program, [(vbo, "3f 3f", "in_position", "in_radiance")])
    previous = ctx.fbo  # bound again afterwards: nobody is left on a released fbo
    try:
        # --- PASS 1: clear to the background
        target.clear(scene.render.background)
        # --- PASS 2: the solved meshes, radiance interpolated across each triangle
        ctx.enable_only(moderngl.DEPTH_TEST)
        program["u_clip_from_world"].write(gl_matrix(view.clip_from_world))
        vao.render(moderngl.TRIANGLES)
        return target.read()
    finally:
        rebind(ctx, previous)
        vao.release()
        vbo.release()
        target.release()


def render_solution(solution, size: tuple[int, int], conforming: bool = True) -> np.ndarray:
    """GL image of a :class:`RadiositySolution` (radiance L = B / pi)."""
    return render_meshes(solution.scene, solution.display_meshes(conforming), size)
