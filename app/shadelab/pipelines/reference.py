"""``reference``: the numpy reference raster (ray cast + Phong-mode shading), rows at a time.

Always available: it checks the GPU image pixel for pixel and exercises the job panel."""

from __future__ import annotations

from typing import Iterator

import numpy as np

from shadelab.pipelines.base import BasePipeline
from shadelab.pipelines.registry import register
from shadelab.progress import Progress
from shadelab.scene.camera import primary_rays
from shadelab.scene.model import Scene
from shadelab.scene.preset import clone_scene


def iter_reference_raster(scene: Scene, size: tuple[int, int], rows_per_chunk: int = 8,
                          off=()):
    """A CPU render with the numpy reference (ray cast + Phong-mode shading, no S_i), rows
    at a time; ``off``: the equation's terms switched off (shade_terms' ``off``)."""
    from shadelab.geometry.mesh import scene_meshes
    from shadelab.lab.probe import Picker, _facing
    from shadelab.shading.reference import normalize, shade

    scene = clone_scene(scene)
    width, height = size
    meshes = scene_meshes(scene)
    picker = Picker(scene, meshes)
    origins, directions = primary_rays(scene.camera, width, height)
    image = np.zeros((height, width, 3), np.float32)
    eye = np.asarray(scene.camera.eye, dtype=np.float64)
    for y0 in range(0, height, rows_per_chunk):
        o = origins[y0:y0 + rows_per_chunk].reshape(-1, 3)
        d = directions[y0:y0 + rows_per_chunk].reshape(-1, 3)
        mesh_id, face, t, bary = picker.hits(o, d)
        out = np.zeros((len(o), 3))
        for m, mesh in enumerate(meshes):
            sel = np.flatnonzero(mesh_id == m)
            if not len(sel):
                continue
            f = face[sel]
            p = o[sel] + t[sel, None] * d[sel]
            n = normalize(np.einsum("ij,ijk->ik", bary[sel], mesh.corner_normals[f]))
            n = _facing(n, mesh.face_normals[f], normalize(eye - p))
            out[sel] = shade(p, n, eye, scene.materials[mesh.material], scene.active_lights(),
                             scene.Ia, scene.render.specular, off=off)
        image[y0:y0 + rows_per_chunk] = out.reshape(-1, width, 3)
        done = min(y0 + rows_per_chunk, height)
        yield Progress(image.copy(), done / height, f"rows {done}/{height}")
    yield Progress(image, 1.0, "done", {"pixels": width * height})


class ReferencePipeline(BasePipeline):
    name = "reference"
    label = "numpy reference (Phong)"
    default_size = (800, 600)
    job_label = "Reference raster (numpy)"
    job_order = 1

    def run(self, scene: Scene, size: tuple[int, int]) -> Iterator[Progress]:
        return iter_reference_raster(scene, size)


register(ReferencePipeline())
