"""Whitted ray tracing: error against time over recursion depth and samples per pixel.

The reference is the same scene traced much deeper with many more samples (another jitter
seed); each setting's error is measured against it on the whole image. The ray-casting
accelerator is built once, so times are tracing only: the best of a few runs, since other
processes on the machine only ever add time.
"""

from __future__ import annotations

import numpy as np

from shadelab.scene.model import Scene
from shadelab.studies import metrics
from shadelab.studies.result import StudyResult, study_clock

COLUMNS = ["depth", "spp", "time_ms", "mae", "rmse", "relmse", "flip"]
PRESET = "whitted"   # a mirror and a glass sphere over a checkerboard: depth matters




def trace(scene: Scene, size: tuple[int, int], depth: int, spp: int, ctx, seed: int = 0):
    """The finished Whitted image (H, W, 3) float64 and its wall time in milliseconds."""
    from shadelab.raytrace.whitted import iter_raytrace

    start = study_clock()
    steps = list(iter_raytrace(scene, size, depth, spp, seed=seed, ctx=ctx))
    last = steps[-1]
    return np.asarray(last.image, dtype=np.float64), (study_clock() - start) * 1000.0


def measure(scene: Scene, size: tuple[int, int], depths, spps, reference: tuple[int, int],
            repeats: int = 1) -> list[list]:
    """Rows of :data:`COLUMNS` for every (depth, spp) against a (depth, spp) reference."""
    from shadelab.raytrace.surface import TraceContext

    ctx = TraceContext(scene)
    ref, _ = trace(scene, size, reference[0], reference[1], ctx, seed=12345)
    settings = [(depth, spp) for spp in spps for depth in depths]
    best = {key: float("inf") for key in settings}
    errors = {}
    for _ in range(repeats):  # rounds over all settings spread the machine's load evenly
        for depth, spp in settings:
            image, ms = trace(scene, size, depth, spp, ctx)
            best[(depth, spp)] = min(best[(depth, spp)], ms)
            errors[(depth, spp)] = metrics.all_metrics(image, ref)
    return [[depth, spp, best[(depth, spp)], errors[(depth, spp)]["mae"],
             errors[(depth, spp)]["rmse"], errors[(depth, spp)]["relmse"],
             errors[(depth, spp)]["flip"]]
            for depth, spp in settings]


def run_raytrace(quick: bool = False) -> StudyResult:
    """Error vs time of the Whitted tracer on cornell-spheres over depth and spp."""
    from shadelab.scene.preset import load_preset

    scene = load_preset(PRESET)
    if quick:
        size, depths, spps, reference, repeats = (40, 40), (0, 1, 2, 4), (1, 4), (8, 16), 1
    else:
        size, depths, spps, reference, repeats = ((128, 128), (0, 1, 2, 3, 4, 6, 8),
                                                  (1, 2, 4, 8, 16), (16, 64), 3)
    rows = measure(scene, size, depths, spps, reference, repeats)
    by_depth = StudyResult(
        name="raytrace-depth", title="Ray tracing: error vs depth", columns=list(COLUMNS),
        rows=rows, x="depth", y="relmse", group="spp", log_x=False)
    return StudyResult(
        name="raytrace", title=f"Whitted ({PRESET}, {size[0]}x{size[1]}): error vs time",
        columns=list(COLUMNS), rows=rows, x="time_ms", y="relmse", group="spp", label="depth",
        notes=[f"reference: depth {reference[0]}, {reference[1]} spp (other jitter seed)",
               "series: samples per pixel; labels: recursion depth",
               "time: process CPU time, best of the rounds (shadelab.studies.result.study_clock)"],
        extra={"depth": by_depth})


def auto_raytrace(scene: Scene, size: tuple[int, int], budget: float,
                  max_side: int = 48) -> tuple[int, int, str]:
    """The cheapest (depth, spp) whose relative MSE meets ``budget``, measured on a small
    probe of the scene itself; returns depth, spp and a report line."""
    from shadelab.studies.autoquality import check_budget, choose_setting, front_from_rows

    budget = check_budget(budget)
    scale = min(1.0, max_side / max(size))
    probe = (max(8, round(size[0] * scale)), max(8, round(size[1] * scale)))
    rows = measure(scene, probe, (0, 1, 2, 3, 4, 6, 8), (1, 2, 4, 8, 16), (16, 64))
    records = [dict(zip(COLUMNS, row, strict=True)) for row in rows]
    choice = choose_setting(front_from_rows(records, ("depth", "spp"), "time_ms"), budget)
    depth, spp = int(choice.point.setting["depth"]), int(choice.point.setting["spp"])
    verdict = "<=" if choice.met else "> (best reachable)"
    return depth, spp, (f"auto quality: depth {depth}, spp {spp}: relMSE "
                        f"{choice.point.error:.3g} {verdict} {budget:g}")
