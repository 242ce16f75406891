"""Flat, Gouraud and Phong shading against an exact per-pixel sphere, over tessellation.

The reference intersects every camera ray with the exact sphere and shades the hit with the
exact normal through :func:`shadelab.shading.reference.shade`; the raster image draws an icosphere
at subdivision level 0..5 with the GL renderer. Errors are taken on pixels both cover, less a
one-pixel border (the silhouette mismatch is reported apart); frame times are the best of
several GL renders + readback.
"""

from __future__ import annotations

import copy

import numpy as np

from shadelab.scene.camera import primary_rays
from shadelab.scene.model import Camera, Light, Material, Object, Scene
from shadelab.shading.reference import shade
from shadelab.studies import metrics
from shadelab.studies.result import StudyResult, study_clock

LEVELS = tuple(range(6))                 # icosphere subdivision levels studied
METHODS = ("flat", "gouraud", "phong")   # raster shading modes
COLUMNS = ["method", "level", "triangles", "time_ms", "mae", "rmse", "relmse", "silhouette",
           "relmse_both", "flip"]


def study_scene() -> Scene:
    """A unit sphere with a tight Phong highlight, lit from the upper right."""
    scene = Scene(description="shading study: unit sphere, one point light", Ia=(0.2, 0.2, 0.2))
    scene.camera = Camera(eye=(0.0, 0.4, 3.6), target=(0.0, 0.0, 0.0), fov_y=38.0, near=0.1)
    scene.lights = [Light(kind="point", position=(2.5, 3.0, 3.5), Ip=(1.0, 1.0, 1.0))]
    scene.materials = {"paint": Material(ka=0.2, kd=0.6, ks=0.5, n=40.0, Od=(0.9, 0.35, 0.2))}
    scene.objects = [Object(shape="sphere", name="sphere", material="paint", radius=1.0,
                            subdivisions=3, normals="average")]
    return scene


def sphere_of(obj: Object) -> tuple[np.ndarray, float] | None:
    """Centre and radius of a sphere object; None when it is not a round sphere."""
    if obj.shape != "sphere":
        return None
    scale = np.abs(np.asarray(obj.scale, dtype=np.float64))
    if np.ptp(scale) > 1e-9 * scale.max():
        return None  # an ellipsoid: no exact reference here
    return np.asarray(obj.translate, dtype=np.float64), float(obj.radius * scale[0])


def exact_sphere_image(scene: Scene, index: int, size: tuple[int, int],
                       specular: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Exact per-pixel shading of sphere object ``index`` alone: image (H, W, 3) and mask."""
    obj = scene.objects[index]
    found = sphere_of(obj)
    if found is None:
        raise ValueError(f"objects.{index} is not a round sphere")
    centre, radius = found
    width, height = size
    origins, dirs = primary_rays(scene.camera, width, height)
    # Solve |o + t d - c|^2 = r^2 for the nearest t > 0 (d is unit)
    oc = origins - centre
    b = np.sum(oc * dirs, axis=-1)
    c = np.sum(oc * oc, axis=-1) - radius * radius
    disc = b * b - c
    hit = disc >= 0.0
    root = np.sqrt(np.maximum(disc, 0.0))
    t = np.where(-b - root > 0.0, -b - root, -b + root)
    hit &= t > 0.0
    image = np.zeros((height, width, 3), dtype=np.float64)
    if hit.any():
        p = origins[hit] + t[hit, None] * dirs[hit]
        n = (p - centre) / radius
        eye = np.asarray(scene.camera.eye, dtype=np.float64)
        n = np.where((np.sum(n * (eye - p), axis=-1) < 0.0)[:, None], -n, n)  # seen from inside
        image[hit] = shade(p, n, eye, scene.material_of(obj), scene.active_lights(), scene.Ia,
                           specular or scene.render.specular)
    return image, hit


def isolated(scene: Scene, index: int, level: int | None = None) -> Scene:
    """A copy of the scene holding only object ``index`` (at subdivision ``level``), drawn
    the way the exact reference shades it: opaque, no texture, bump, shadows or painter."""
    out = copy.deepcopy(scene)
    obj = out.objects[index]
    if level is not None:
        obj.subdivisions = level
    out.objects = [obj]
    out.render.background = (0.0, 0.0, 0.0)
    out.render.shadows = "none"            # one object: nothing to cast on it
    out.render.visibility = "zbuffer"
    material = out.materials[obj.material]
    material.texture, material.bump = "", ""  # the exact reference shades plain Od,
    material.kt = 0.0                         # opaque (no blend with what lies behind)
    return out


def coverage(scene: Scene, size: tuple[int, int]) -> np.ndarray:
    """(H, W) bool: the pixels the raster renderer covers (an emission-only render)."""
    from shadelab.raster.offscreen import render_image

    masked = copy.deepcopy(scene)
    masked.materials = {"mask": Material(ka=0.0, kd=0.0, ks=0.0, emission=(1.0, 1.0, 1.0))}
    for obj in masked.objects:
        obj.material = "mask"
    masked.render.background = (0.0, 0.0, 0.0)
    return render_image(masked, size, "flat")[..., 0] > 0.5


def interior(mask: np.ndarray) -> np.ndarray:
    """``mask`` without its one-pixel border (4-neighbourhood erosion).

    Along the silhouette the polyhedron and the sphere cover different pixels (counted apart
    as 'silhouette'), and a depth tie between a front and a back facet there can show the
    back facet, lit through its flipped normal: a one-pixel speck that says nothing about
    shading. The errors are taken inside.
    """
    out = mask.copy()
    out[1:, :] &= mask[:-1, :]
    out[:-1, :] &= mask[1:, :]
    out[:, 1:] &= mask[:, :-1]
    out[:, :-1] &= mask[:, 1:]
    out[0, :] = out[-1, :] = False
    out[:, 0] = out[:, -1] = False
    return out


def timed_render(scene: Scene, size: tuple[int, int], shading: str, specular: str | None,
                 repeats: int) -> tuple[np.ndarray, float]:
    """The raster image and the best frame time of ``repeats`` (render + readback), ms."""
    from shadelab.raster.offscreen import render_image

    image = render_image(scene, size, shading, specular)  # warm-up: upload, compile
    samples = []
    for _ in range(repeats):
        start = study_clock()
        image = render_image(scene, size, shading, specular)
        samples.append((study_clock() - start) * 1000.0)
    return image, min(samples)


def measure_sphere(scene: Scene, index: int, shading: str, size: tuple[int, int],
                   levels=LEVELS, specular: str | None = None, repeats: int = 5) -> list[list]:
    """Rows of :data:`COLUMNS` for one sphere object over tessellation ``levels``."""
    reference, ref_mask = exact_sphere_image(scene, index, size, specular)
    rows = []
    for level in levels:
        single = isolated(scene, index, level)
        image, ms = timed_render(single, size, shading, specular, repeats)
        covered = coverage(single, size)
        both, either = covered & ref_mask, covered | ref_mask
        silhouette = float(np.mean(either & ~both)) if either.any() else 0.0
        mask = interior(both)
        errors = metrics.all_metrics(image, reference, mask)
        triangles = 20 * 4 ** level
        rows.append([shading, level, triangles, ms, errors["mae"], errors["rmse"],
                     errors["relmse"], silhouette, metrics.relmse(image, reference, both),
                     errors["flip"]])
    return rows


def run_shading(quick: bool = False) -> StudyResult:
    """Error against frame time for flat, Gouraud and Phong over icosphere levels 0..5."""
    scene = study_scene()
    size = (96, 96) if quick else (256, 256)
    repeats = 3 if quick else 9
    rows = []
    for method in METHODS:
        rows.extend(measure_sphere(scene, 0, method, size, LEVELS, repeats=repeats))
    by_triangles = StudyResult(
        name="shading-triangles", title="Shading: error vs triangle count", columns=list(COLUMNS),
        rows=rows, x="triangles", y="relmse", group="method")
    return StudyResult(
        name="shading", title=f"Shading: error vs frame time (sphere, {size[0]}x{size[1]})",
        columns=list(COLUMNS), rows=rows, x="time_ms", y="relmse", group="method",
        label="level",
        notes=["reference: exact ray-sphere hit, exact normal, shadelab.shading.reference.shade",
               "error on pixels covered by both, less a 1-px border; 'silhouette' = share covered "
               "by one only; 'relmse_both' = relMSE on every pixel covered by both",
               "time: best of several GL render + readback, CPU time of the process (llvmpipe's "
               "threads included; shadelab.studies.result.study_clock)"],
        extra={"triangles": by_triangles})

