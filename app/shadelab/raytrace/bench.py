"""Ray tracing figures for ``shadelab bench``: Whitted rays/s on cornell-spheres (512 x 512,
depth 5, 1 spp, shading included) beside Embree's raw primary-ray throughput on the same
scene, the numba BVH's, and the path tracer's samples/s on cornell."""

from __future__ import annotations

import time

import numpy as np

from shadelab.raytrace.accel import BvhAccel, EmbreeAccel, embree_available, scene_geometry
from shadelab.raytrace.pathtrace import PathTracer
from shadelab.raytrace.surface import TraceContext
from shadelab.raytrace.whitted import iter_raytrace
from shadelab.scene.camera import primary_rays
from shadelab.scene.preset import load_preset
from shadelab.timing import median_time


def _cpu_ms(fn, repeats: int) -> float:
    """Median process CPU time of ``fn`` in ms (steadier than wall time on a shared machine)."""
    samples = []
    for _ in range(repeats):
        start = time.process_time()
        fn()
        samples.append((time.process_time() - start) * 1000.0)
    return float(np.median(samples))


def _whitted(size: tuple[int, int], repeats: int) -> dict:
    scene = load_preset("cornell-spheres")
    start = time.perf_counter()
    ctx = TraceContext(scene)
    setup_ms = (time.perf_counter() - start) * 1000.0
    last = {}

    def render():
        for step in iter_raytrace(scene, size, depth=5, spp=1, ctx=ctx):
            last["stats"] = step.stats

    timing = median_time(render, repeats, warmup=1)
    cpu_ms = _cpu_ms(render, repeats)
    stats = last["stats"]
    seconds = timing["median_ms"] / 1000.0
    return {"scene": "cornell-spheres", "size": list(size), "depth": 5, "spp": 1,
            "backend": ctx.accel.name, "setup_ms": setup_ms, **timing, "cpu_median_ms": cpu_ms,
            "rays": stats["rays"], "primary_rays": stats["primary_rays"],
            "secondary_rays": stats["secondary_rays"], "shadow_rays": stats["shadow_rays"],
            "depth_reached": stats["depth_reached"], "rays_per_s": stats["rays"] / seconds,
            "rays_per_cpu_s": stats["rays"] / (cpu_ms / 1000.0)}


def _raw_primary(size: tuple[int, int], repeats: int) -> dict:
    """Rays/s of the accelerators alone on the same primary rays (float32, no shading)."""
    scene = load_preset("cornell-spheres")
    geometry = scene_geometry(scene)
    o, d = primary_rays(scene.camera, *size)
    o, d = o.reshape(-1, 3), d.reshape(-1, 3)
    out = {}
    if embree_available():
        embree = EmbreeAccel(geometry)
        o32, d32 = o.astype(np.float32), d.astype(np.float32)
        def raw():
            embree._all.run(o32, d32, output=1)  # noqa: SLF001

        timing = median_time(raw, repeats)
        cpu_ms = _cpu_ms(raw, repeats)
        out["embree_raw"] = {**timing, "cpu_median_ms": cpu_ms,
                             "rays_per_s": len(o) / (timing["median_ms"] / 1000.0),
                             "rays_per_cpu_s": len(o) / (cpu_ms / 1000.0)}
    bvh = BvhAccel(geometry)
    timing = median_time(lambda: bvh.intersect(o, d), max(3, repeats // 2))
    out["bvh"] = {**timing, "rays_per_s": len(o) / (timing["median_ms"] / 1000.0)}
    return out


def _pathtrace(size: tuple[int, int], spp: int, repeats: int) -> dict:
    scene = load_preset("cornell")
    tracer = PathTracer(scene)
    o, d = primary_rays(scene.camera, *size)
    o, d = o.reshape(-1, 3), d.reshape(-1, 3)
    rng = np.random.default_rng(0)

    def render():
        for _ in range(spp):
            tracer.radiance(o, d, rng)

    tracer.rays = 0
    timing = median_time(render, repeats, warmup=1)
    samples = size[0] * size[1] * spp
    seconds = timing["median_ms"] / 1000.0
    return {"scene": "cornell", "size": list(size), "spp": spp, **timing,
            "samples_per_s": samples / seconds,
            "rays_per_sample": tracer.rays / (samples * (repeats + 1)),
            "backend": tracer.ctx.accel.name}


def run(quick: bool) -> dict:
    size = (512, 512)
    repeats = 3 if quick else 7
    whitted = _whitted(size, repeats)
    raw = _raw_primary(size, repeats)
    report = {"whitted": whitted, "primary_raw": raw,
              "pathtrace": _pathtrace((64, 64) if quick else (128, 128), 4 if quick else 8,
                                      2 if quick else 5)}
    if "embree_raw" in raw:
        # Goal >= 0.5; the CPU-time ratio is the steadier one on a loaded machine
        report["whitted_vs_raw_embree"] = whitted["rays_per_s"] / raw["embree_raw"]["rays_per_s"]
        report["whitted_vs_raw_embree_cpu"] = (whitted["rays_per_cpu_s"]
                                               / raw["embree_raw"]["rays_per_cpu_s"])
    return report
