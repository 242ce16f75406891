"""Radiosity: error against time over patch count, hemicube resolution, form-factor method
and solver, and each solver's convergence.

Every setting is solved from scratch on the Cornell box (uniform patches, so the count is
what was asked) and drawn from the scene camera; its error is the image's relative MSE
against a reference solved with many more patches, ray-cast form factors and the direct
solver. Time is meshing + form factors + solve (best of the runs).
"""

from __future__ import annotations

import numpy as np

from shadelab.scene.model import Scene
from shadelab.studies import metrics
from shadelab.studies.result import StudyResult, study_clock

COLUMNS = ["series", "label", "patches", "form_factors", "resolution", "solver", "time_ms",
           "mae", "rmse", "relmse", "flip"]
CONVERGENCE_COLUMNS = ["solver", "iteration", "time_ms", "residual"]
MESHING_COLUMNS = ["meshing", "target", "patches", "time_ms", "l1"]
PRESET = "cornell"




def solve_timed(scene: Scene, patches: int, method: str, resolution: int, solver: str,
                repeats: int = 1):
    """(solution, milliseconds: best of ``repeats``) for a uniform-patch solve."""
    from shadelab.radiosity.solution import solve_scene
    from shadelab.raster.hemicube import Hemicube  # the GPU backend of hemicube form factors

    best = float("inf")
    for _ in range(repeats):
        start = study_clock()
        solution = solve_scene(scene, patches, method, solver, adaptive=False,
                               resolution=resolution, hemicube=Hemicube, meshing="uniform")
        best = min(best, (study_clock() - start) * 1000.0)
    return solution, best


def _row(series, label, solution, method, resolution, solver, ms, image, reference):
    errors = metrics.all_metrics(image, reference)
    return [series, str(label), len(solution.patches), method, resolution, solver, ms,
            errors["mae"], errors["rmse"], errors["relmse"], errors["flip"]]


def convergence(solution, solver: str) -> list[list]:
    """Rows of :data:`CONVERGENCE_COLUMNS` from a solution's history (unshot for progressive)."""
    history = solution.stats.get("history", {})
    rows = []
    for it, res, unshot, t in zip(history.get("iteration", []), history.get("residual", []),
                                  history.get("unshot", []), history.get("time_s", []),
                                  strict=False):
        value = unshot if np.isnan(res) else res
        if np.isfinite(value) and value > 0:
            rows.append([solver, it, t * 1000.0, value])
    return rows


def meshing_table(scene: Scene, quick: bool = False) -> StudyResult:
    """Error against wall time, uniform against discontinuity meshing, both against a
    converged path-traced reference (relative L1 away from the light, the bench's metric:
    :func:`shadelab.bench.radiosity.error_in_budget` gives the same series at 32 x 32 and
    16k spp; the quick table uses 16 x 16 and 2 x 512 spp, cached on disk)."""
    from shadelab.bench import radiosity as bench
    from shadelab.radiosity.solution import solve_scene

    size, spp, counts = ((16, 16), 512, (100, 300)) if quick else \
        (bench.ERROR_SIZE, bench.REFERENCE_SPP, (200, 400, 600, 800, 1000, 1200))
    reference, images, _ = bench.converged_reference(scene, size, spp)
    mask = bench.emitter_ring_mask(solve_scene(scene, 100, adaptive=False, meshing="uniform"),
                                   size)
    rows = []
    for meshing in ("uniform", "discontinuity"):
        solve_scene(scene, 20, adaptive=False, meshing=meshing)  # warm-up
        for r in bench.error_vs_time(scene, size, reference, mask, counts, meshing):
            rows.append([meshing, r["target"], r["patches"], r["seconds"] * 1000.0,
                         r["error"]])
    floor = bench.reference_noise(images, mask)
    return StudyResult(
        name="radiosity-meshing",
        title=f"Radiosity: error vs time by meshing (against {2 * spp} spp path tracing)",
        columns=list(MESHING_COLUMNS), rows=rows, x="time_ms", y="l1", group="meshing",
        label="patches",
        notes=[f"relative L1 away from the light, {size[0]}x{size[1]} pixels, radiosity "
               f"{bench.SUPERSAMPLE}x{bench.SUPERSAMPLE} sub-pixels; reference's own noise "
               f"~{floor:.2%}",
               "time: wall seconds of meshing + ray-cast form factors + Gauss-Seidel",
               "discontinuity: hidden cells dropped, penumbra cells split (radiosity.meshing)"])


def run_radiosity(quick: bool = False) -> StudyResult:
    """Error vs time over patches, form factors, hemicube resolution and solvers (Cornell)."""
    from shadelab.scene.preset import load_preset

    scene = load_preset(PRESET)
    if quick:
        size, ref_patches, counts, resolutions, fixed, repeats = (40, 40), 300, \
            (25, 50, 100), (8, 32), 60, 1
    else:
        size, ref_patches, counts, resolutions, fixed, repeats = (96, 96), 1600, \
            (25, 50, 100, 200, 400, 800), (4, 8, 16, 32, 64, 128, 256), 200, 2
    for method, solver in (("raycast", "jacobi"), ("hemicube", "gauss-seidel"),
                           ("analytic", "progressive")):
        solve_timed(scene, 8, method, 8, solver)          # warm-up: JIT, GL context
    ref_solution, _ = solve_timed(scene, ref_patches, "raycast", 128, "direct")
    reference = np.asarray(ref_solution.image(size), dtype=np.float64)
    rows, conv = [], []
    for method in ("raycast", "hemicube", "analytic"):
        for count in counts:
            sol, ms = solve_timed(scene, count, method, 64, "direct", repeats)
            rows.append(_row(method, count, sol, method, 64, "direct", ms, sol.image(size),
                             reference))
    for resolution in resolutions:
        sol, ms = solve_timed(scene, fixed, "hemicube", resolution, "direct", repeats)
        rows.append(_row("hemicube-resolution", resolution, sol, "hemicube", resolution,
                         "direct", ms, sol.image(size), reference))
    for solver in ("direct", "jacobi", "gauss-seidel", "progressive"):
        sol, ms = solve_timed(scene, fixed, "raycast", 64, solver, repeats)
        rows.append(_row("solver", solver, sol, "raycast", 64, solver, ms, sol.image(size),
                         reference))
        if solver != "direct":  # one step, residual at rounding level
            conv.extend(convergence(sol, solver))
    convergence_table = StudyResult(
        name="radiosity-convergence", title="Radiosity: convergence per solver",
        columns=list(CONVERGENCE_COLUMNS), rows=conv, x="time_ms", y="residual",
        group="solver")
    return StudyResult(
        name="radiosity", title=f"Radiosity ({PRESET}, {size[0]}x{size[1]}): error vs time",
        columns=list(COLUMNS), rows=rows, x="time_ms", y="relmse", group="series",
        label="label",
        notes=[f"reference: {len(ref_solution.patches)} uniform patches, ray-cast form "
               f"factors, direct solve",
               "series raycast/hemicube/analytic: patch count sweep (hemicube at 64 px)",
               f"hemicube-resolution: {fixed} patches; solver: {fixed} patches, ray-cast",
               "convergence: relative residual (progressive: unshot energy share) against "
               "solver time; Jacobi and Gauss-Seidel start from a finished F, progressive "
               "refinement computes its rows of F as it shoots",
               "'analytic' form factors ignore occlusion (the blocks): a biased floor",
               "time: process CPU time (shadelab.studies.result.study_clock)"],
        extra={"convergence": convergence_table, "meshing": meshing_table(scene, quick)})


def auto_radiosity(scene: Scene, size: tuple[int, int], budget: float,
                   method: str | None = None, max_side: int = 48,
                   counts=(25, 50, 100, 200)) -> tuple[int, int, str]:
    """The cheapest uniform patch count (and hemicube resolution, for hemicube form factors)
    whose image meets ``budget`` in relative MSE against a 4x finer ray-cast solve of the
    scene itself; returns patches, resolution and a report line."""
    from shadelab.studies.autoquality import check_budget, choose_setting, front_from_rows

    budget = check_budget(budget)
    method = method or scene.radiosity.form_factors
    scale = min(1.0, max_side / max(size))
    probe = (max(8, round(size[0] * scale)), max(8, round(size[1] * scale)))
    ref, _ = solve_timed(scene, 4 * max(counts), "raycast", 128, "direct")
    reference = np.asarray(ref.image(probe), dtype=np.float64)
    resolutions = (16, 32, 64, 128) if method == "hemicube" else \
        (scene.radiosity.hemicube_resolution,)
    records = []
    for count in counts:
        for resolution in resolutions:
            sol, ms = solve_timed(scene, count, method, resolution, "direct")
            error = metrics.relmse(np.asarray(sol.image(probe), dtype=np.float64), reference)
            records.append({"patches": count, "resolution": resolution, "time_ms": ms,
                            "relmse": error})
    choice = choose_setting(front_from_rows(records, ("patches", "resolution"), "time_ms"),
                            budget)
    patches, resolution = choice.point.setting["patches"], choice.point.setting["resolution"]
    verdict = "<=" if choice.met else "> (best reachable)"
    detail = f", hemicube {resolution} px" if method == "hemicube" else ""
    return patches, resolution, (f"auto quality: {patches} patches{detail}: relMSE "
                                 f"{choice.point.error:.3g} {verdict} {budget:g}")
