"""Radiosity bench section: time to an image within 5 % of the converged path-traced
reference, for radiosity and for the reference path tracer, in the same run; and the time
to a first lit image with progressive refinement.

Error metric (``image_error``): relative L1, sum |img - ref| / sum |ref|, over the pixels
that do not see an emitter or touch one (a one-pixel ring, diagonals included). Both images
are box-filtered pixels: the path tracer's jittered samples, radiosity's 16 x 16 sub-pixel
centres (4 x 4 left a coverage error at every silhouette and room edge that dominated the
metric: Cornell 32 x 32, 2400 uniform patches against 16k spp, 2.1 % at 4 x 4, 1.7 % at
8 x 8, 1.2 % at 16 x 16 -- the pixels' geometry, not the illumination). The light's
own pixels hold Le in both by definition; at its edges a 0.04-pixel difference in sampling
swings those pixels (L = 20 against ~0.2 on the walls) more than all the rest of the image,
so they would measure sampling of the light's outline, not illumination.
"""

from __future__ import annotations

import hashlib
import math
import tempfile
import time
from pathlib import Path

import numpy as np

TARGET = 0.05  # relative error the timings aim for
SUPERSAMPLE = 16  # radiosity sub-pixels per side for the comparison
BUDGET_S = 2.0  # wall time for ``radiosity_error_in_2s`` (meshing + form factors + solve)
ERROR_SIZE = (32, 32)  # pixels of the error-vs-time comparison (its 16k-spp reference's
#                        own noise is ~0.6 % there; at 64 x 64 it would be ~1.2 %)
REFERENCE_SPP = 8192  # per seed; two seeds averaged: 16k spp
REFERENCE_SEEDS = (101, 202)


def emitter_ring_mask(solution, size: tuple[int, int]) -> np.ndarray:
    """(H, W) bool: pixels that neither see an emitter nor neighbour one that does."""
    from shadelab.radiosity.solution import RadiositySolution

    p = solution.patches
    lit = RadiositySolution(solution.scene, p, p.E).image(size, supersample=SUPERSAMPLE)
    hit = np.pad(lit.max(axis=2) > 0.0, 1)
    ring = np.zeros_like(hit)
    for dy in (-1, 0, 1):  # 3 x 3 dilation
        for dx in (-1, 0, 1):
            ring[1:-1, 1:-1] |= hit[1 + dy:hit.shape[0] - 1 + dy, 1 + dx:hit.shape[1] - 1 + dx]
    return ~ring[1:-1, 1:-1]


def image_error(image: np.ndarray, reference: np.ndarray, mask: np.ndarray) -> float:
    """Relative L1 error over the masked pixels."""
    a = np.asarray(image, np.float64)[mask]
    b = np.asarray(reference, np.float64)[mask]
    return float(np.abs(a - b).sum() / max(np.abs(b).sum(), 1e-300))


def radiosity_image(scene, size, patches: int, solver: str = "gauss-seidel",
                    adaptive: bool = False,
                    method: str = "raycast", meshing: str = "uniform"):
    """(solution, supersampled CPU image) of one solve."""
    from shadelab.radiosity.solution import solve_scene

    solution = solve_scene(scene, patches, method, solver, adaptive=adaptive, meshing=meshing)
    return solution, solution.image(size, supersample=SUPERSAMPLE)


def time_radiosity(scene, size, reference, counts, mask=None) -> dict:
    """Solve at increasing patch counts; the first one within TARGET, with its wall time."""
    rows = []
    for count in counts:
        start = time.perf_counter()
        solution, image = radiosity_image(scene, size, count)
        seconds = time.perf_counter() - start
        if mask is None:
            mask = emitter_ring_mask(solution, size)
        error = image_error(image, reference, mask)
        rows.append({"patches": len(solution.patches), "seconds": seconds, "error": error})
        if error <= TARGET:
            break
    hit = next((r for r in rows if r["error"] <= TARGET), None)
    return {"runs": rows, "seconds_to_target": hit["seconds"] if hit else None,
            "patches_at_target": hit["patches"] if hit else None}, mask


def cache_dir() -> Path:
    """Where the converged references are kept: ShadeLab's cache (``SHADELAB_CACHE_DIR``,
    :func:`shadelab.geometry.cache.cache_root`), or a temporary folder when it is off."""
    from shadelab.geometry.cache import cache_root

    root = cache_root()
    return Path(tempfile.gettempdir()) / "shadelab-cache" if root is None else root


def converged_reference(scene, size, spp: int = REFERENCE_SPP,
                        seeds=REFERENCE_SEEDS) -> tuple[np.ndarray, list[np.ndarray], dict]:
    """(mean image, one image per seed, info) of independent path-traced renders, cached on
    disk under :func:`cache_dir` by a hash of the scene, size, spp and seed (minutes to make
    once: 32 x 32 x 8192 spp is ~50 s a seed on one core). The seeds' images give the
    reference's own noise: ``info["noise_floor"]`` is set by :func:`reference_noise`."""
    from shadelab.raytrace.pathtrace import render_pathtraced

    key = hashlib.sha1(repr(scene).encode()).hexdigest()[:16]
    folder = cache_dir() / "radiosity-reference"
    images, made_s, cached = [], 0.0, True
    for seed in seeds:
        path = folder / f"{key}-{size[0]}x{size[1]}-{spp}spp-seed{seed}.npy"
        try:
            cached_image = np.load(path, allow_pickle=False)
        except (OSError, ValueError, EOFError):   # not made yet, or damaged: render it
            cached_image = None
        if cached_image is not None and cached_image.shape == (size[1], size[0], 3):
            images.append(cached_image)
            continue
        cached = False
        start = time.perf_counter()
        image = render_pathtraced(scene, size, spp, seed=seed)
        made_s += time.perf_counter() - start
        try:
            folder.mkdir(parents=True, exist_ok=True)
            np.save(path, image)
        except OSError:                           # a read-only cache: use it uncached
            pass
        images.append(image)
    mean = np.mean([np.asarray(i, np.float64) for i in images], axis=0)
    return mean, images, {"spp": spp * len(seeds), "seeds": list(seeds), "size": list(size),
                          "cached": cached, "render_s": made_s, "folder": str(folder)}


def reference_noise(images: list[np.ndarray], mask: np.ndarray) -> float:
    """Expected relative L1 of the mean of ``images`` against the truth: the seeds' mutual
    error divided by sqrt(2) per seed pair and by sqrt(k) for the k-image mean (for two
    images: half their mutual error)."""
    if len(images) < 2:
        return float("nan")
    pair = image_error(images[0], images[1], mask)  # ~ sqrt(2) * one image's noise
    return float(pair / math.sqrt(2.0) / math.sqrt(len(images)))


def error_vs_time(scene, size, reference, mask, counts, meshing: str,
                  budget_s: float | None = None) -> list[dict]:
    """Rows (patches, seconds, cpu_s, error) of runs at increasing patch counts: ``seconds``
    is the wall time of meshing + ray-cast form factors + the preset's solver (what
    ``shadelab radiosity`` runs; the image is not timed), ``cpu_s`` the process's CPU time
    over the same span (the work is single-threaded: what an idle core takes, readable on a
    loaded machine); stops after the first run over ``budget_s`` past the budget (to show
    the trend)."""
    from shadelab.radiosity.solution import solve_scene

    rows = []
    for count in counts:
        start, cpu = time.perf_counter(), time.process_time()
        solution = solve_scene(scene, count, "raycast", None, adaptive=False,
                               meshing=meshing)
        seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
        image = solution.image(size, supersample=SUPERSAMPLE)
        rows.append({"target": int(count), "patches": len(solution.patches),
                     "seconds": seconds, "cpu_s": cpu,
                     "error": image_error(image, reference, mask)})
        if budget_s is not None and seconds > 1.5 * budget_s:
            break
    return rows


def best_within(rows: list[dict], budget_s: float) -> dict | None:
    """The lowest-error row whose seconds are within the budget (None: none is)."""
    inside = [r for r in rows if r["seconds"] <= budget_s]
    return min(inside, key=lambda r: r["error"]) if inside else None


def error_in_budget(scene, quick: bool) -> dict:
    """``radiosity_error_in_2s`` and the error-vs-time series for uniform and discontinuity
    meshing against the cached 16k-spp reference (:data:`ERROR_SIZE` pixels)."""
    size = ERROR_SIZE
    reference, images, info = converged_reference(scene, size)
    counts = (300, 600, 800, 1000, 1100) if quick else \
        (200, 400, 600, 800, 900, 1000, 1100, 1200, 1600)
    series, mask = {}, None
    for meshing in ("uniform", "discontinuity"):
        from shadelab.radiosity.solution import solve_scene

        solve_scene(scene, 20, "raycast", None, adaptive=False, meshing=meshing)
        if mask is None:
            mask = emitter_ring_mask(solve_scene(scene, 100, adaptive=False, meshing="uniform"),
                                     size)
        series[meshing] = error_vs_time(scene, size, reference, mask, counts, meshing,
                                        budget_s=BUDGET_S)
    info["noise_floor"] = reference_noise(images, mask)
    best = {m: best_within(rows, BUDGET_S) for m, rows in series.items()}
    errors = [b["error"] for b in best.values() if b is not None]
    return {"radiosity_error_in_2s": min(errors) if errors else None,
            "best_in_2s": best, "goal": 0.015, "budget_s": BUDGET_S, "size": list(size),
            "supersample": SUPERSAMPLE, "reference": info, "error_vs_time": series,
            "defaults": at_defaults(scene, size, reference, mask),
            "solver": scene.radiosity.solver,
            "timed": "meshing + ray-cast form factors + the preset's solver, single process"}


def at_defaults(scene, size, reference, mask, repeats: int = 3) -> dict:
    """``shadelab radiosity cornell`` as a user runs it (the preset's patches, meshing,
    form factors and solver): median seconds of ``repeats`` solves, and the error."""
    from shadelab.radiosity.solution import solve_scene

    seconds, cpu, solution = [], [], None
    for _ in range(repeats):
        start, cpu_start = time.perf_counter(), time.process_time()
        solution = solve_scene(scene)
        seconds.append(time.perf_counter() - start)
        cpu.append(time.process_time() - cpu_start)
    image = solution.image(size, supersample=SUPERSAMPLE)
    return {"patches": len(solution.patches), "meshing": solution.stats["meshing"],
            "solver": solution.stats["solver"], "seconds": float(np.median(seconds)),
            "samples_s": seconds, "cpu_s": float(np.median(cpu)),
            "error": image_error(image, reference, mask)}


def time_pathtracer(scene, size, reference, mask, spps, seed: int = 7) -> dict:
    """Full renders at increasing samples per pixel (each a fresh job: the tracer stratifies
    over the spp it is given); the first one within TARGET, with its wall time."""
    from shadelab.raytrace.pathtrace import render_pathtraced

    rows = []
    for spp in spps:
        start = time.perf_counter()
        image = render_pathtraced(scene, size, spp, seed=seed)
        seconds = time.perf_counter() - start
        rows.append({"spp": spp, "seconds": seconds,
                     "error": image_error(image, reference, mask)})
        if rows[-1]["error"] <= TARGET:
            break
    hit = next((r for r in rows if r["error"] <= TARGET), None)
    return {"runs": rows, "seconds_to_target": hit["seconds"] if hit else None,
            "spp_at_target": hit["spp"] if hit else None}


def first_lit_image(scene, size, patches: int, repeats: int = 3) -> dict:
    """Seconds from the call to the first Progress with a lit image (progressive refinement)."""
    from shadelab.radiosity.solution import iter_radiosity

    samples = []
    for _ in range(repeats):
        start = time.perf_counter()
        job = iter_radiosity(scene, size, patches, "raycast", "progressive", meshing="uniform")
        try:
            for step in job:
                if step.image is not None and float(step.image.max()) > 0.0:
                    samples.append(time.perf_counter() - start)
                    break
        finally:
            job.close()
    return {"median_s": float(np.median(samples)), "samples_s": samples, "patches": patches,
            "size": list(size)}


def radiosity_scaling(scene, quick: bool) -> dict:
    """Seconds against patch count, form factors (ray-cast matrix) and the solve (Gauss-
    Seidel) apart, each with its fitted exponent (expected ~2 for both: N^2 pairs, N^2 per
    sweep)."""
    from shadelab.radiosity.formfactors import FormFactors
    from shadelab.radiosity.patches import uniform_patches
    from shadelab.radiosity.solvers import solve_gauss_seidel
    from shadelab.timing import scaling

    counts = (100, 200, 400) if quick else (100, 200, 400, 800, 1600)
    patches, ff_s, solve_s = [], [], []
    warm = uniform_patches(scene, 50)  # numba kernels loaded before the first timed point
    for _ in solve_gauss_seidel(FormFactors(warm, "raycast").matrix(), warm.rho, warm.emission):
        pass
    for count in counts:
        p = uniform_patches(scene, count)
        start = time.perf_counter()
        F = FormFactors(p, "raycast").matrix()
        ff_s.append(time.perf_counter() - start)
        E = np.pi * p.emission
        start = time.perf_counter()
        for _ in solve_gauss_seidel(F, p.rho, E):
            pass
        solve_s.append(time.perf_counter() - start)
        patches.append(len(p))
    return {"form_factors": scaling(patches, ff_s, "patches"),
            "solve_gauss_seidel": scaling(patches, solve_s, "patches")}


def run(quick: bool) -> dict:
    """Bench figures for cornell (quick: 16x16 comparisons, fewer samples)."""
    from shadelab.raytrace.pathtrace import render_pathtraced
    from shadelab.scene.preset import load_preset

    scene = load_preset("cornell")
    size = (32, 32) if quick else (64, 64)
    ref_spp = 1024 if quick else 2048
    counts = (200, 300, 400, 600, 800, 1000) if quick else (200, 300, 400, 600, 800, 1000, 1200)
    # Warm up: numba JIT (cached), embree, the GL context is not needed (CPU images)
    radiosity_image(scene, (8, 8), 20)
    render_pathtraced(scene, (4, 4), 1, seed=3)
    start = time.perf_counter()
    reference = render_pathtraced(scene, size, ref_spp, seed=1001)
    ref_seconds = time.perf_counter() - start
    radiosity, mask = time_radiosity(scene, size, reference, counts)
    spps = [2 ** k for k in range(5, 13) if 2 ** k <= ref_spp // 4]
    pathtracer = time_pathtracer(scene, size, reference, mask, spps)
    ratio = None
    if radiosity["seconds_to_target"] and pathtracer["seconds_to_target"]:
        ratio = pathtracer["seconds_to_target"] / radiosity["seconds_to_target"]
    first = first_lit_image(scene, (64, 64), 400, repeats=3)
    # The path tracer's cost grows with the pixels at a given error per pixel; radiosity's
    # does not (one solve, then any image): the same figures at the CLI's 512 x 512
    scale = (512 * 512) / (size[0] * size[1])
    projected = None
    if radiosity["seconds_to_target"] and pathtracer["seconds_to_target"]:
        projected = {"size": [512, 512],
                     "pathtracer_s": pathtracer["seconds_to_target"] * scale,
                     "radiosity_s": radiosity["seconds_to_target"],
                     "speedup": pathtracer["seconds_to_target"] * scale
                     / radiosity["seconds_to_target"],
                     "assumption": "path-tracer time scales with pixel count at fixed spp; "
                                   "radiosity image time (< 0.1 s) neglected"}
    return {
        "scene": "cornell", "size": list(size), "target_relative_error": TARGET,
        "metric": "relative L1 over pixels away from the light (1-pixel ring excluded); "
                  f"radiosity {SUPERSAMPLE}x{SUPERSAMPLE} supersampled, ray-cast form factors, "
                  "Gauss-Seidel, uniform "
                  "patches; both single-threaded",
        "reference": {"spp": ref_spp, "seconds": ref_seconds, "seed": 1001},
        "radiosity": radiosity, "pathtracer": pathtracer,
        "speedup_radiosity_vs_pathtracer": ratio, "speedup_goal": 3.0,
        "projected_512": projected,
        "first_lit_image_progressive": first, "first_lit_image_goal_s": 0.5,
        "scaling_vs_patches": radiosity_scaling(scene, quick),
        **_in_budget(scene, quick),
    }


def _in_budget(scene, quick: bool) -> dict:
    figure = error_in_budget(scene, quick)
    return {"radiosity_error_in_2s": figure["radiosity_error_in_2s"],
            "radiosity_error_vs_time": figure}
