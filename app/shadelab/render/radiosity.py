"""One call from a scene to its radiosity image (the failure gallery and scripts use it)."""

from __future__ import annotations

import numpy as np

from shadelab.scene.model import Scene


def render_radiosity(scene: Scene, size: tuple[int, int], gl: bool = True) -> np.ndarray:
    """Solve with the scene's ``[radiosity]`` settings; (H, W, 3) float32 radiance.

    ``gl``: draw the Gouraud-shaded meshes with the GL program (default), else by CPU rays.
    """
    from shadelab.radiosity.solution import solve_scene

    solution = solve_scene(scene)
    if not gl:
        return solution.image(size)
    from shadelab.radiosity.display_gl import render_solution

    return render_solution(solution, size)
