"""Whitted's recursive ray tracer on the CPU, traced breadth-first over many rays at once.

For each pixel sample the lecture's equation is evaluated recursively,

    I = Le + Ia ka Od + sum_i S_i f_att,i Ip,i [kd Od (N.L_i) + ks Os (R_i.V)^n] + kr I_r + kt I_t

with S_i from shadow rays, kr = ``Material.mirror`` (kr, or ks where kr is unset) and kt the
transmission coefficient (or Fresnel's F and 1 - F with ``fresnel``). Because I is linear in
I_r and I_t, a ray tree is the sum of its nodes' local colors times the products of the
weights on the way down: each generation of rays is traced as one batch (a "wavefront"),
and a ray whose weight falls below ``min_weight`` is not spawned.

The image is linear RGB, aligned pixel for pixel with the raster view (same camera, same
triangles, the same interpolated normals as Phong shading, the same local model).
"""

from __future__ import annotations

import math
import time
from typing import Iterator

import numpy as np

from app.errors import ShadeLabError
from app.progress import Progress
from app.raytrace.surface import TraceContext
from app.scene.camera import primary_rays
from app.scene.model import Scene

TILE_RAYS = 32768  # primary rays per work unit (keeps a chunk well under 0.2 s)


def stratified_jitter(spp: int, sample: int, shape: tuple[int, int],
                      rng: np.random.Generator) -> np.ndarray | None:
    """(H, W, 2) offsets in [0, 1) for one sample of a stratified pattern; None at 1 spp.

    The pixel is cut into an nx x ny grid (nx = ceil(sqrt(spp))); sample s jitters inside
    cell (s mod nx, s div nx). One sample per pixel goes through the pixel centre, as the
    raster samples.
    """
    if spp <= 1:
        return None
    nx = math.ceil(math.sqrt(spp))
    ny = math.ceil(spp / nx)
    cx, cy = sample % nx, sample // nx
    jitter = rng.random(shape + (2,))
    jitter[..., 0] = (cx + jitter[..., 0]) / nx
    jitter[..., 1] = (cy + jitter[..., 1]) / ny
    return jitter


def check_settings(depth: int, spp: int, size: tuple[int, int]) -> None:
    """One-line errors for values the tracer cannot use."""
    if depth < 0:
        raise ShadeLabError(f"--depth {depth}: expected an integer >= 0")
    if spp < 1:
        raise ShadeLabError(f"--spp {spp}: expected an integer >= 1")
    if size[0] < 1 or size[1] < 1:
        raise ShadeLabError(f"--size {size[0]}x{size[1]}: expected each side >= 1")


class WavefrontStats:
    """Counters for the figures a render reports."""

    def __init__(self, shadow_start: int = 0):
        self.shadow_start = shadow_start  # the context's shadow-ray counter at the start
        self.primary = 0
        self.primary_hits = 0
        self.secondary = 0
        self.depth_reached = 0

    def as_dict(self, ctx: TraceContext, elapsed: float) -> dict:
        shadow = ctx.shadow_rays - self.shadow_start
        total = self.primary + self.secondary + shadow
        return {"primary_rays": self.primary, "primary_hits": self.primary_hits,
                "secondary_rays": self.secondary,
                "shadow_rays": shadow, "rays": total,
                "depth_reached": self.depth_reached, "seconds": elapsed,
                "rays_per_s": total / elapsed if elapsed > 0 else 0.0,
                "backend": ctx.accel.name}


def trace_batch(ctx: TraceContext, origins: np.ndarray, dirs: np.ndarray, depth: int,
                fresnel: bool, stats: WavefrontStats | None = None,
                min_weight: float | None = None) -> np.ndarray:
    """Radiance (N, 3) along N rays, recursing to ``depth`` bounces, generation by generation."""
    n = len(origins)
    out = np.zeros((n, 3))
    stats = WavefrontStats() if stats is None else stats
    min_weight = ctx.scene.raytrace.min_weight if min_weight is None else min_weight
    pixel = np.arange(n)
    weight = np.ones((n, 3))
    for generation in range(depth + 1):
        if len(origins) == 0:
            break
        if generation:
            stats.secondary += len(origins)
            stats.depth_reached = max(stats.depth_reached, generation)
        else:
            stats.primary += len(origins)
        hits = ctx.accel.intersect(origins, dirs)
        # Misses see the background
        miss = ~hits.hit
        _accumulate(out, pixel[miss], weight[miss] * ctx.background)
        hit = np.flatnonzero(hits.hit)
        if generation == 0:
            stats.primary_hits += len(hit)
        if len(hit) == 0:
            break
        o, d, w, px = origins[hit], dirs[hit], weight[hit], pixel[hit]
        sub = type(hits)(hits.t[hit], hits.tri[hit], hits.u[hit], hits.v[hit])
        surf = ctx.surface(o, d, sub)
        _accumulate(out, px, w * ctx.local(surf, d))
        if generation == depth:
            break
        # Spawn the reflected and refracted generation
        origins, dirs, weight, pixel = ctx.spawn(surf, d, w, px, fresnel, min_weight)
    return out


def _accumulate(out: np.ndarray, pixel: np.ndarray, value: np.ndarray) -> None:
    if len(pixel):
        for c in range(3):
            out[:, c] += np.bincount(pixel, weights=value[:, c], minlength=len(out))


def iter_raytrace(scene: Scene, size: tuple[int, int], depth: int | None = None,
                  spp: int | None = None, fresnel: bool | None = None,
                  backend: str = "auto", shadows: bool = True, seed: int = 0,
                  ctx: TraceContext | None = None) -> Iterator[Progress]:
    """Trace the scene progressively: one :class:`Progress` per tile of rows per pass.

    Parameters
    ----------
    scene : the Scene, with its camera, lights and raytrace settings
    size : (width, height) pixels
    depth, spp, fresnel : override ``scene.raytrace`` (None keeps the preset's)
    backend : "auto" | "embree" | "bvh"
    shadows : False for S_i = 1 everywhere (compare with the raster without volumes)
    seed : random seed of the stratified jitter

    Yields
    ------
    Progress with the image so far (H, W, 3) float32 linear, each pixel averaged over the
    samples it has; stats hold ray counts, rays/s and the depth reached.
    """
    settings = scene.raytrace
    depth = settings.depth if depth is None else int(depth)
    spp = settings.spp if spp is None else int(spp)
    fresnel = settings.fresnel if fresnel is None else bool(fresnel)
    check_settings(depth, spp, size)
    width, height = size
    ctx = TraceContext(scene, backend, shadows) if ctx is None else ctx
    stats = WavefrontStats(ctx.shadow_rays)
    rng = np.random.default_rng(seed)
    total = np.zeros((height * width, 3))
    count = np.zeros(height * width)
    image = np.zeros((height, width, 3), np.float32)
    rows = max(1, TILE_RAYS // width)
    tiles = [(r, min(r + rows, height)) for r in range(0, height, rows)]
    start = time.perf_counter()
    for sample in range(spp):
        jitter = stratified_jitter(spp, sample, (height, width), rng)
        origins, dirs = primary_rays(scene.camera, width, height, jitter)
        for t, (r0, r1) in enumerate(tiles):
            o = origins[r0:r1].reshape(-1, 3)
            d = dirs[r0:r1].reshape(-1, 3)
            rows_done = slice(r0 * width, r1 * width)
            total[rows_done] += trace_batch(ctx, o, d, depth, fresnel, stats)
            count[rows_done] += 1
            image[r0:r1] = (total[rows_done] / count[rows_done, None]).reshape(r1 - r0, width, 3)
            done = (sample * len(tiles) + t + 1) / (spp * len(tiles))
            yield Progress(image.copy(), done,
                           f"pass {sample + 1}/{spp}, rows {r1}/{height}",
                           stats.as_dict(ctx, time.perf_counter() - start))


def render_raytraced(scene: Scene, size: tuple[int, int], depth: int | None = None,
                     spp: int | None = None, fresnel: bool | None = None,
                     backend: str = "auto", shadows: bool = True) -> np.ndarray:
    """The finished ray-traced image (H, W, 3) float32 linear."""
    last = None
    for step in iter_raytrace(scene, size, depth, spp, fresnel, backend, shadows):
        last = step
    return last.image
