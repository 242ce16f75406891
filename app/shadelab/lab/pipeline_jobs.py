"""The offline pipelines of the viewport as worker-process jobs (pure: numpy, no GL, no GUI).

Each factory ``f(scene, size)`` yields :class:`shadelab.progress.Progress` and pickles by
reference, so :class:`shadelab.lab.jobs.JobRunner` runs it in its worker process:

* ray tracing and path tracing render coarse first: 1/8 of the viewport's resolution, then
  1/4, 1/2 and full, each a complete picture, refined in place;
* radiosity shoots patch by patch (progressive refinement) and sends the Gouraud display
  triangles after each chunk of shots, with the patch that shot last; the GPU draws them under
  the live camera. Its patches and form-factor rows stay in the worker between jobs, so a
  material or emission edit re-solves without re-meshing (``stats["form_factors_reused"]``).
"""

from __future__ import annotations

import math
import time
from typing import Iterator

import numpy as np

from shadelab.progress import Progress
from shadelab.scene.model import Scene
from shadelab.scene.preset import clone_scene

LEVELS = (8, 4, 2, 1)        # resolution divisors, coarse to fine
RADIOSITY_CHUNK_S = 0.05     # seconds of shooting between two radiosity updates
_RADIOSITY_CACHE: dict = {}  # worker process: geometry key -> (patches, form factors, token)


def level_size(size: tuple[int, int], divisor: int) -> tuple[int, int]:
    return max(1, size[0] // divisor), max(1, size[1] // divisor)


def _held_back(steps: Iterator[Progress]) -> Iterator[Progress]:
    """Yield every step but the last one late, marked done: the viewer polls only the newest
    Progress, so the final one must carry the final image (not a bare 'done')."""
    last = None
    for step in steps:
        if last is not None:
            yield last
        last = step
    if last is not None:
        last.fraction, last.stats = 1.0, dict(last.stats, done=True)
        last.message = "done: " + last.message
        yield last


def pipeline_raytrace(scene: Scene, size: tuple[int, int]) -> Iterator[Progress]:
    """Whitted at 1/8, 1/4, 1/2 and full resolution (the scene's spp only at full)."""
    return _held_back(_raytrace_levels(scene, size))


def _raytrace_levels(scene: Scene, size: tuple[int, int]) -> Iterator[Progress]:
    from shadelab.raytrace.surface import TraceContext
    from shadelab.raytrace.whitted import iter_raytrace

    ctx = TraceContext(scene)
    rays = 0
    for li, div in enumerate(LEVELS):
        sub = level_size(size, div)
        spp = scene.raytrace.spp if div == 1 else 1
        level_rays = 0
        for step in iter_raytrace(scene, sub, spp=spp, ctx=ctx):
            level_rays = int(step.stats.get("rays", 0))
            yield Progress(step.image, (li + step.fraction) / len(LEVELS),
                           f"1/{div} resolution ({sub[0]}x{sub[1]}), {step.message}, "
                           f"{rays + level_rays} rays",
                           {"level": div, "size": sub, "rays": rays + level_rays,
                            "unit": "rays"})
        rays += level_rays


def pipeline_pathtrace(scene: Scene, size: tuple[int, int]) -> Iterator[Progress]:
    """The path tracer at 1/8, 1/4, 1/2 resolution (1 sample), then full at the scene's spp."""
    return _held_back(_pathtrace_levels(scene, size))


def _pathtrace_levels(scene: Scene, size: tuple[int, int]) -> Iterator[Progress]:
    from shadelab.raytrace.pathtrace import iter_pathtrace

    samples = 0
    spp_full = max(int(scene.raytrace.spp), 1)
    for li, div in enumerate(LEVELS):
        sub = level_size(size, div)
        spp = spp_full if div == 1 else 1
        level = 0
        for step in iter_pathtrace(scene, sub, spp, seed=1):
            level = int(round(step.fraction * spp * sub[0] * sub[1]))
            yield Progress(step.image, (li + step.fraction) / len(LEVELS),
                           f"1/{div} resolution ({sub[0]}x{sub[1]}), {step.message}, "
                           f"{samples + level} samples",
                           {"level": div, "size": sub, "samples": samples + level,
                            "unit": "samples"})
        samples += level


def radiosity_key(scene: Scene) -> str:
    """What the patches and form factors depend on: geometry and meshing, not materials."""
    s = scene.radiosity
    objects = [(o.shape, o.material, o.path, o.radius, o.minor_radius, o.height, o.extents,
                o.size, tuple(map(tuple, o.vertices)), o.subdivisions, o.sections, o.segments,
                o.translate, o.rotate, o.scale) for o in scene.objects]
    return repr((objects, scene.base_dir, s.patches, ff_method(scene), s.hemicube_resolution))


def ff_method(scene: Scene) -> str:
    """The worker has no GL context: the GPU hemicube becomes ray-cast form factors there."""
    method = scene.radiosity.form_factors
    return "raycast" if method == "hemicube" else method


def soup(vertices_faces_colors: list) -> np.ndarray:
    """(3F, 6) float32 position and radiance per corner (the viewport's triangle format)."""
    parts = [np.concatenate([np.asarray(v)[f].reshape(-1, 3), np.asarray(c)[f].reshape(-1, 3)],
                            axis=1) for v, f, c in vertices_faces_colors if len(f)]
    if not parts:
        return np.zeros((0, 6), np.float32)
    return np.ascontiguousarray(np.concatenate(parts), dtype=np.float32)


def _reflectance(scene: Scene, patches) -> tuple[np.ndarray, np.ndarray]:
    """rho = kd Od and Le per patch from the scene's current materials."""
    rho, emission = np.zeros((len(patches), 3)), np.zeros((len(patches), 3))
    for index, surface in enumerate(patches.surfaces):
        material = scene.materials[surface.material]
        mask = patches.surface == index
        rho[mask] = material.kd * np.asarray(material.Od, float)
        emission[mask] = material.emission
    return rho, emission


def pipeline_radiosity(scene: Scene, size: tuple[int, int] | None = None,
                       step_shots: int = 0) -> Iterator[Progress]:
    """Radiosity shot by shot; ``stats``: display ``soup``, ``shooter`` (4, 3) corners,
    ``history``, ``patches``, ``form_factors_reused`` and the form factors' ``ff_token``.
    ``step_shots`` > 0 yields after every that many shots (the step button)."""
    from shadelab.radiosity import display
    from shadelab.radiosity.formfactors import FormFactors
    from shadelab.radiosity.patches import check_count, uniform_patches
    from shadelab.radiosity.solution import check_scene
    from shadelab.radiosity.solvers import check_solvable, run_solver

    settings = scene.radiosity
    check_count(settings.patches, "radiosity.patches")
    check_scene(scene)
    start = time.perf_counter()
    key = radiosity_key(scene)
    cached = _RADIOSITY_CACHE.get(key)
    reused = cached is not None
    if cached is None:
        yield Progress(None, 0.0, "meshing", {"unit": "patches"})
        patches = uniform_patches(scene, settings.patches)
        ff = FormFactors(patches, ff_method(scene), settings.hemicube_resolution)
        cached = (patches, ff, f"ff-{time.time_ns()}")
        _RADIOSITY_CACHE.clear()  # one geometry at a time: the rows can be large
        _RADIOSITY_CACHE[key] = cached
    patches, ff, token = cached
    rho, emission = _reflectance(scene, patches)
    E = math.pi * emission
    n = len(patches)
    base = {"patches": n, "form_factors": ff.method, "solver": settings.solver,
            "form_factors_reused": reused, "ff_token": token, "unit": "patches"}
    shooter = [-1]

    def row(i: int) -> np.ndarray:
        shooter[0] = i
        return ff.row(i)

    if settings.solver == "progressive":
        steps = run_solver("progressive", None, rho, E, settings.iterations, settings.tolerance,
                           row=row, areas=patches.areas)
    else:
        yield Progress(None, 0.05, f"form factors ({n} patches)", dict(base))
        F = ff.matrix()
        check_solvable(F, rho)
        steps = run_solver(settings.solver, F, rho, E, settings.iterations, settings.tolerance,
                           areas=patches.areas)
    history = {"iteration": [], "residual": [], "unshot": []}
    last, last_yield, since = None, 0.0, 0
    for last in steps:
        history["iteration"].append(last.iteration)
        history["residual"].append(float(last.residual))
        history["unshot"].append(float(last.unshot))
        since += 1
        now = time.perf_counter()
        if step_shots > 0 and since < step_shots:
            continue
        if step_shots <= 0 and now - last_yield < RADIOSITY_CHUNK_S and last.iteration > 1:
            continue
        since, last_yield = 0, now
        yield _radiosity_progress(patches, rho, last, shooter[0], history, base, start,
                                  display, ff, final=False, settings=settings)
    if last is None:
        return
    yield _radiosity_progress(patches, rho, last, shooter[0], history, base, start, display,
                              ff, final=True, settings=settings)


def _radiosity_progress(patches, rho, step, shooter, history, base, start, display, ff,
                        final: bool, settings) -> Progress:
    B = step.display_B(rho)
    meshes = display.display_meshes(patches, B / math.pi, True)
    value = step.unshot if np.isnan(step.residual) else step.residual
    tol = max(settings.tolerance, 1e-12)
    fraction = 1.0 if final or not value > tol else \
        min(0.99, math.log(max(value, 1e-300)) / math.log(tol)) if value < 1.0 else 0.0
    what = (f"shot {step.iteration}, unshot {step.unshot:.2e}" if np.isnan(step.residual)
            else f"iteration {step.iteration}, residual {step.residual:.2e}")
    stats = dict(base, soup=soup(meshes), history={k: list(v) for k, v in history.items()},
                 shots=step.iteration, elapsed_s=time.perf_counter() - start,
                 rows=len(ff._rows), done=final)
    if shooter >= 0:
        stats["shooter"] = np.asarray(patches.polygons[shooter], np.float32)
        stats["shooter_index"] = int(shooter)
    return Progress(None, max(fraction, 0.0), ("done: " if final else "") + what
                    + f" ({len(patches)} patches)", stats)


def warm_kernels(scene: Scene | None, size) -> Iterator[Progress]:
    """Compile or load every numba kernel (Whitted, path tracer, radiosity) on a tiny scene,
    so the first lesson image does not wait for the JIT. Yields once per renderer."""
    from shadelab.scene.preset import load_preset

    tiny = clone_scene(scene) if scene is not None else load_preset("cornell")
    try:
        cornell = load_preset("cornell")
    except Exception:  # a renamed preset must not break the viewer's start
        cornell = tiny
    cornell.radiosity.patches = 24
    cornell.radiosity.solver = "progressive"
    cornell.radiosity.iterations = 2
    stages = (("whitted", lambda: pipeline_raytrace(tiny, (8, 8))),
              ("path tracer", lambda: pipeline_pathtrace(_one_spp(tiny), (8, 8))),
              ("radiosity", lambda: pipeline_radiosity(cornell, None)))
    for i, (name, make) in enumerate(stages):
        t0 = time.perf_counter()
        try:
            for _ in make():
                pass
        except Exception:  # a scene a renderer refuses (no emitter...) still warms the rest
            pass
        yield Progress(None, (i + 1) / len(stages), f"warmed {name}",
                       {f"warm_{name}_s": time.perf_counter() - t0})
    _RADIOSITY_CACHE.clear()


def _one_spp(scene: Scene) -> Scene:
    scene = clone_scene(scene)
    scene.raytrace.spp = 1
    return scene


def warm_pipeline(scene: Scene | None, name: str) -> Iterator[Progress]:
    """The worker's first task when the viewer starts in an offline pipeline: import that
    pipeline's renderer and load (or compile) its kernels on an 8x8 image / 24 patches, while
    the window opens, so the first real job finds them ready. Yields nothing (job id 0)."""
    from shadelab.scene.preset import load_preset

    try:
        tiny = clone_scene(scene) if scene is not None else load_preset("cornell")
        if name == "radiosity":
            tiny.radiosity.patches = 24
            tiny.radiosity.solver = "progressive"
            tiny.radiosity.iterations = 2
            gen = pipeline_radiosity(tiny, None)
        elif name == "pathtrace":
            gen = pipeline_pathtrace(_one_spp(tiny), (8, 8))
        else:
            gen = pipeline_raytrace(tiny, (8, 8))
        for _ in gen:
            pass
    except Exception:  # a scene the renderer refuses: its real job reports why
        pass
    _RADIOSITY_CACHE.clear()
    return iter(())
