"""Stencil shadow volumes against the CPU shadow-ray oracle: mismatch share and time.

For each pixel the oracle traces the primary ray to the visible surface (the raster's
triangles, same camera) and a shadow ray to each light; the stencil count of the GL renderer
(z-fail or z-pass) must agree with it: S_i = 0 exactly where the count is non-zero. Pixels
whose surface faces away from a light are left out (both give them no direct light).
"""

from __future__ import annotations

import numpy as np

from shadelab.errors import ShadeLabError
from shadelab.scene.camera import primary_rays
from shadelab.scene.model import Scene
from shadelab.scene.preset import load_preset
from shadelab.studies.result import StudyResult, study_clock

COLUMNS = ["scene", "method", "triangles", "time_ms", "oracle_ms", "mismatch"]
SCENES = ("shadows", "shadows-colored", "fail-open-caster", "fail-zpass-eye-inside")
METHODS = ("zfail", "zpass")
LEVELS = (1, 2, 3, 4, 5)   # caster sphere subdivisions in the "shadows" preset sweep


def oracle_masks(scene: Scene, size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """(L, H, W) shadowed-by-ray and (L, H, W) valid (hit, facing the light) masks."""
    from shadelab.raytrace.accel import T_INF
    from shadelab.raytrace.surface import TraceContext

    width, height = size
    ctx = TraceContext(scene, "auto", shadows=True)
    origins, dirs = primary_rays(scene.camera, width, height)
    o, d = origins.reshape(-1, 3), dirs.reshape(-1, 3)
    hits = ctx.accel.intersect(o, d, np.full(len(o), T_INF))
    hit = hits.hit
    lights = scene.active_lights()
    shadowed = np.zeros((len(lights), height * width), bool)
    valid = np.zeros((len(lights), height * width), bool)
    if hit.any():
        idx = np.flatnonzero(hit)
        surf = ctx.surface(o[idx], d[idx], _subset(hits, idx))
        factors = ctx.shadow_factors(surf)
        from shadelab.shading.reference import light_vectors

        for i, light in enumerate(lights):
            to_light, _ = light_vectors(light, surf.position)
            facing = np.einsum("ij,ij->i", surf.geo_normal, to_light) > 0.0
            valid[i, idx] = facing
            shadowed[i, idx] = facing & (factors[i] == 0.0)
    return (shadowed.reshape(len(lights), height, width),
            valid.reshape(len(lights), height, width))


def _subset(hits, idx):
    from shadelab.raytrace.accel import Hits

    return Hits(hits.t[idx], hits.tri[idx], hits.u[idx], hits.v[idx])


def stencil_masks(scene: Scene, size: tuple[int, int]) -> np.ndarray:
    """(L, H, W) True where the GL stencil count for light i is non-zero."""
    from shadelab.raster.offscreen import shared_renderer, shared_target
    from shadelab.raster.shadows import shadow_masks

    return shadow_masks(shared_renderer(), scene, shared_target(size))


def mismatch(stencil: np.ndarray, shadowed: np.ndarray, valid: np.ndarray) -> float:
    """Share of valid pixel-light pairs on which the stencil and the oracle disagree."""
    if not valid.any():
        return 0.0
    return float(np.mean(stencil[valid] != shadowed[valid]))


def frame_ms(scene: Scene, size: tuple[int, int], repeats: int) -> float:
    """Best frame time of ``repeats`` (render with shadow volumes + readback), milliseconds."""
    from shadelab.raster.offscreen import render_image

    render_image(scene, size)
    samples = []
    for _ in range(repeats):
        start = study_clock()
        render_image(scene, size)
        samples.append((study_clock() - start) * 1000.0)
    return min(samples)


def measure(scene: Scene, size: tuple[int, int], method: str, repeats: int) -> list:
    """One row of :data:`COLUMNS` (without the scene name) for ``scene`` drawn with ``method``."""
    from shadelab.geometry.mesh import scene_meshes

    scene.render.shadows = "volumes"
    scene.render.shadow_method = method
    start = study_clock()
    shadowed, valid = oracle_masks(scene, size)
    oracle = (study_clock() - start) * 1000.0
    share = mismatch(stencil_masks(scene, size), shadowed, valid)
    triangles = sum(len(m.faces) for m in scene_meshes(scene))
    return [method, triangles, frame_ms(scene, size, repeats), oracle, share]


def run_shadows(quick: bool = False) -> StudyResult:
    """Stencil volumes (z-fail, z-pass) against shadow rays on the shadow presets."""
    size = (64, 48) if quick else (240, 180)
    repeats = 2 if quick else 7
    rows, skipped = [], []
    for name in SCENES:
        try:
            base = load_preset(name)
        except ShadeLabError as exc:  # a preset of another layer not written yet
            skipped.append(f"skipped {name}: {exc}")
            continue
        for method in METHODS:
            rows.append([name, *measure(base, size, method, repeats)])
    sweep = []
    for level in LEVELS[:3] if quick else LEVELS:
        scene = load_preset("shadows", [f"objects.1.subdivisions={level}"])
        for method in METHODS:
            sweep.append([f"sphere-{level}", *measure(scene, size, method, repeats)])
    by_triangles = StudyResult(
        name="shadows-sweep", title="Shadow volumes: frame time vs caster triangles",
        columns=list(COLUMNS), rows=sweep, x="triangles", y="time_ms", group="method")
    return StudyResult(
        name="shadows", title=f"Shadow volumes vs shadow rays ({size[0]}x{size[1]})",
        columns=list(COLUMNS), rows=rows + sweep, x="time_ms", y="mismatch", group="method",
        label="scene", lines=False, front=False,
        notes=["mismatch: share of pixel-light pairs (surface facing the light) where the "
               "stencil count and the CPU shadow ray disagree",
               "fail-zpass-eye-inside: the eye is inside a volume, z-pass inverts the count",
               "time: process CPU time (llvmpipe threads included; study_clock)",
               *skipped],
        extra={"sweep": by_triangles})
