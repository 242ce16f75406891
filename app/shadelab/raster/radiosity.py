"""Radiosity with the GPU at hand: the pure solver (:mod:`shadelab.radiosity.solution`) bound
to the GL hemicube backend, and one call from a scene to its radiosity image (the failure
gallery, the command line and scripts use it).

``python -m shadelab.raster.radiosity OUTDIR`` writes the radiosity failure gallery's pictures
(:mod:`shadelab.radiosity.gallery`; item images need EGL).
"""

from __future__ import annotations

import sys
from functools import partial
from pathlib import Path

import numpy as np

from shadelab.radiosity import solution
from shadelab.raster.hemicube import Hemicube, item_images
from shadelab.raster.radiosity_image import render_solution
from shadelab.scene.model import Scene

# The solver's entry points with hemicube form factors available (GL backend passed in).
iter_radiosity = partial(solution.iter_radiosity, hemicube=Hemicube)
solve_scene = partial(solution.solve_scene, hemicube=Hemicube)
precheck = solution.precheck


def render_radiosity(scene: Scene, size: tuple[int, int], gl: bool = True) -> np.ndarray:
    """Solve with the scene's ``[radiosity]`` settings; (H, W, 3) float32 radiance.

    ``gl``: draw the Gouraud-shaded meshes with the GL program (default), else by CPU rays.
    """
    solved = solve_scene(scene)
    if not gl:
        return solved.image(size)
    return render_solution(solved, size)


# ---------------------------------------------------------------------- the failure gallery
def write_gallery(folder: str, size: tuple[int, int] = (256, 256)) -> list[str]:
    """Write the gallery's pictures (PNG) into ``folder``; returns the paths."""
    from shadelab.imageio import write_png
    from shadelab.radiosity.gallery import light_leak, small_patch_scene, t_vertex_cracks

    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    leak = light_leak()
    for name in ("unsplit", "split"):
        path = out / f"leak_{name}.png"
        write_png(str(path), render_solution(leak[f"{name}_solution"], size))
        written.append(str(path))
    cracks = t_vertex_cracks()
    for conforming in (False, True):
        path = out / f"tvertex_{'conforming' if conforming else 'naive'}.png"
        write_png(str(path), render_solution(cracks["solution"], size, conforming))
        written.append(str(path))
    for res in (8, 64):
        patches, _ = small_patch_scene(0.2, 0.5)
        images = item_images(patches, 0, res)
        path = out / f"hemicube_items_{res}.png"
        top = (images["top"] >= 0).astype(np.float32)
        write_png(str(path), np.repeat(np.kron(top, np.ones((256 // res, 256 // res)))[..., None],
                                       3, axis=2))
        written.append(str(path))
    return written


def main(argv: list[str]) -> int:
    folder = argv[0] if argv else "gallery"
    for path in write_gallery(folder):
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
