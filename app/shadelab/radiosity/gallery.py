"""The radiosity failure gallery: each classic artefact as data, a picture and a number.

* Hemicube aliasing: a patch smaller than a hemicube pixel is seen or missed depending on
  where it falls between pixel centres, so its form factor jumps with sub-pixel shifts.
* Light leaking: a block standing on a floor whose patches run under it; the hidden floor
  gets the average of its patch (light "under" the block), and the visible strip beside the
  block is darkened by the hidden part. Cutting the floor along the block's base fixes it.
* T-vertex cracks: adaptive subdivision puts fine corners in the middle of coarse edges;
  drawn naively the two sides interpolate different values along that edge.

The pictures (GL) are written by ``python -m shadelab.raster.radiosity OUTDIR``; this module
stays GL-free, so the hemicube backend is passed in (``hemicube_aliasing(hemicube=...)``).
"""

from __future__ import annotations

import copy

import numpy as np

from shadelab.radiosity.display import crack_report
from shadelab.radiosity.formfactors import FormFactors, check_backend, point_polygon
from shadelab.radiosity.patches import from_polygons, uniform_patches
from shadelab.radiosity.solution import RadiositySolution, _solve_quick, mesh_scene
from shadelab.scene.model import Object, Scene
from shadelab.scene.preset import load_preset

BLOCK_FOOTPRINT = (0.35, 0.65, 0.35, 0.65)  # x0, x1, z0, z1 of radiosity-leak's block


# ---------------------------------------------------------------------- hemicube aliasing
def small_patch_scene(side: float, shift: float) -> tuple:
    """A unit receiver at z = 0 facing +z and a small square of ``side`` at height 1 facing
    down, moved by ``shift`` (a fraction of its own side) along x and y."""
    receiver = [[-0.5, -0.5, 0], [0.5, -0.5, 0], [0.5, 0.5, 0], [-0.5, 0.5, 0]]
    h, d = side / 2.0, shift * side
    small = [[-h + d, -h + d, 1], [-h + d, h + d, 1], [h + d, h + d, 1], [h + d, -h + d, 1]]
    return from_polygons([receiver, small]), np.asarray(small, float)


def hemicube_aliasing(resolutions=(8, 256), side: float = 0.2, shifts=None,
                      hemicube=None) -> dict:
    """F from the receiver's centre to a small square, by hemicube at each resolution, for
    several sub-pixel shifts, against the exact point-to-polygon value.

    ``hemicube``: the GPU backend (:class:`shadelab.raster.hemicube.Hemicube`), required.
    """
    check_backend("hemicube", hemicube)
    shifts = np.linspace(0.0, 1.0, 9) if shifts is None else np.asarray(shifts)
    out = {"shifts": shifts, "exact": [], "hemicube": {int(r): [] for r in resolutions}}
    for shift in shifts:
        patches, small = small_patch_scene(side, float(shift))
        out["exact"].append(point_polygon([0, 0, 0], [0, 0, 1], small))
        for res in resolutions:
            cube = hemicube(patches, int(res))
            out["hemicube"][int(res)].append(float(cube.rows(np.array([0]))[0, 1]))
            cube.release()
    out["exact"] = np.asarray(out["exact"])
    out["relative_error"] = {r: np.asarray(v) / out["exact"] - 1.0
                             for r, v in out["hemicube"].items()}
    return out


# ---------------------------------------------------------------------- light leaking
def split_floor(scene: Scene, footprint=BLOCK_FOOTPRINT) -> Scene:
    """A copy of the leak scene whose floor is cut into 9 quads along the block's base."""
    fixed = copy.deepcopy(scene)
    floor = next(o for o in fixed.objects if o.name == "floor")
    fixed.objects.remove(floor)
    xs = (0.0, footprint[0], footprint[1], 1.0)
    zs = (0.0, footprint[2], footprint[3], 1.0)
    for i in range(3):
        for k in range(3):
            x0, x1, z0, z1 = xs[i], xs[i + 1], zs[k], zs[k + 1]
            fixed.objects.insert(0, Object(shape="quad", name=f"floor_{i}{k}", material="white",
                                           normals="flat", vertices=[[x1, 0, z0], [x0, 0, z0],
                                                                     [x0, 0, z1], [x1, 0, z1]]))
    return fixed


def hidden_floor_radiosity(solution: RadiositySolution, footprint=BLOCK_FOOTPRINT) -> float:
    """Mean radiance the solution assigns to the floor under the block (exact answer: 0)."""
    p = solution.patches
    floor = np.abs(p.normals[:, 1] - 1.0) < 1e-9
    floor &= np.abs(p.centers[:, 1]) < 1e-9
    lo, hi = p.polygons[:, :, [0, 2]].min(axis=1), p.polygons[:, :, [0, 2]].max(axis=1)
    ox = np.clip(np.minimum(hi[:, 0], footprint[1]) - np.maximum(lo[:, 0], footprint[0]), 0, None)
    oz = np.clip(np.minimum(hi[:, 1], footprint[3]) - np.maximum(lo[:, 1], footprint[2]), 0, None)
    overlap = ox * oz * floor
    area = (footprint[1] - footprint[0]) * (footprint[3] - footprint[2])
    luminance = solution.radiance @ np.array([0.2126, 0.7152, 0.0722])
    return float((overlap * luminance).sum() / area)


def light_leak(count: int = 40, method: str = "raycast") -> dict:
    """Hidden-floor radiance with the floor unsplit and split along the block's base."""
    scene = load_preset("radiosity-leak")
    out = {}
    for name, s in (("unsplit", scene), ("split", split_floor(scene))):
        solution = solve_uniform(s, count, method)
        out[name] = hidden_floor_radiosity(solution)
        out[f"{name}_solution"] = solution
    lit = out["split_solution"]
    floor = np.abs(lit.patches.normals[:, 1] - 1.0) < 1e-9
    luminance = lit.radiance[floor] @ np.array([0.2126, 0.7152, 0.0722])
    areas = lit.patches.areas[floor]
    out["lit_floor_mean"] = float((luminance * areas).sum() / areas.sum())
    return out


def solve_uniform(scene: Scene, count: int, method: str = "raycast") -> RadiositySolution:
    """Uniform patches, full form factors and the direct solve (for small teaching cases)."""
    patches = uniform_patches(scene, count)
    F = FormFactors(patches, method).matrix()
    return RadiositySolution(scene, patches, _solve_quick(F, patches), {"patches": len(patches)})


# ---------------------------------------------------------------------- T-vertex cracks
def t_vertex_cracks(count: int = 120, preset: str = "radiosity-leak") -> dict:
    """Crack report of an adaptively refined mesh (naive against conforming display)."""
    scene = load_preset(preset)
    patches = mesh_scene(scene, count, "raycast", adaptive=True)
    F = FormFactors(patches, "raycast").matrix()
    solution = RadiositySolution(scene, patches, _solve_quick(F, patches), {})
    report = crack_report(patches, solution.radiance)
    report["solution"] = solution
    return report
