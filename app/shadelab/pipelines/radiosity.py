"""``radiosity``: patches, form factors, a solver; the solution's Gouraud-shaded triangles.

One driver, two ways to watch it:

* :meth:`RadiosityPipeline.run` (``shadelab.render``, ``shadelab radiosity``, the Offline
  panel): :func:`shadelab.radiosity.solution.iter_radiosity`, the scene's
  ``radiosity.meshing`` (discontinuity meshing by default); the
  last step's ``stats["solution"]`` is the :class:`RadiositySolution`, drawn by
  :meth:`RadiosityPipeline.image` (the GL program, or CPU rays with ``display="cpu"``).
* :meth:`RadiosityPipeline.viewport_job` (the viewer): uniform patches (whatever
  ``radiosity.meshing`` says: the Hemicube & F window numbers the same grid) shot by shot
  (progressive refinement), the display triangles (``stats["soup"]``, from a cached
  :class:`shadelab.radiosity.display.DisplayPlan`) after each chunk of shots with the patch
  that shot last; the GPU draws them under the live camera. The scene's form factors: the
  hemicube on a GL context of the job's own (several likely shooters per atlas), ray-cast where
  none can be made (``stats["form_factors_note"]``); every row computed goes out once in
  ``stats["ff_rows"]`` for the Hemicube & F window. ``radiosity.ambient`` false: the display
  shows the light shot so far, without the ambient estimate. Patches, display plan and
  form-factor rows stay in the worker between jobs, so a material or emission edit re-solves
  without re-meshing (``stats["form_factors_reused"]``). Both mesh with
  :func:`shadelab.radiosity.solution.base_patches` and start the solver through one function,
  :func:`shadelab.radiosity.solution.solver_steps` (right-hand side with the lights' first
  shot, form factors, solvability check): only how the steps are streamed differs.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Iterator

import numpy as np

from shadelab.pipelines.base import TRIANGLES, BasePipeline
from shadelab.pipelines.registry import register
from shadelab.progress import Progress
from shadelab.scene.model import Scene
from shadelab.shading.packing import reflectance

RADIOSITY_CHUNK_S = 0.05     # seconds of shooting between two viewer updates
_RADIOSITY_CACHE: dict = {}  # worker process: geometry key -> (patches, form factors, token)


class RadiosityPipeline(BasePipeline):
    name = "radiosity"
    label = "radiosity + Gouraud"
    output = TRIANGLES
    options = ("patches", "form_factors", "solver", "adaptive", "meshing", "gpu", "display")
    default_size = (512, 512)
    viewport = 4
    job_label = "Radiosity"
    job_order = 4
    compare_shading = "gouraud"
    unit = "patches"

    def check(self, scene: Scene, label: str = "") -> None:
        from shadelab.radiosity.solution import check_scene

        check_scene(scene)

    def run(self, scene: Scene, size: tuple[int, int] | None = None,
            patches: int | None = None, form_factors: str | None = None,
            solver: str | None = None, adaptive: bool = True, meshing: str | None = None,
            gpu: bool = False, display: str = "gl") -> Iterator[Progress]:
        """``gpu``: hemicube form factors on the GL hemicube; ``size``: CPU images on the way
        (None: none, as the CLI and shadelab.render do; they draw the result with GL)."""
        from shadelab.radiosity.solution import iter_radiosity, precheck

        if patches is not None:
            from shadelab.radiosity.patches import check_count

            check_count(patches)
        precheck(scene, patches or scene.radiosity.patches,
                 form_factors or scene.radiosity.form_factors)
        hemicube = None
        if gpu:
            from shadelab.raster.hemicube import Hemicube  # GL only when asked for

            hemicube = Hemicube
        return iter_radiosity(scene, size, patches, form_factors, solver, adaptive=adaptive,
                              hemicube=hemicube, meshing=meshing)

    def image(self, last: Progress, size: tuple[int, int], display: str = "gl",
              **_) -> np.ndarray:
        solution = last.stats["solution"]
        if display == "cpu":
            return solution.image(size)
        from shadelab.raster.radiosity_image import render_solution  # GL only once solved

        return render_solution(solution, size)

    def info(self, last: Progress, options: dict) -> dict:
        return {k: v for k, v in last.stats["solution"].stats.items() if k != "history"}

    def job(self, scene: Scene, size: tuple[int, int]) -> Iterator[Progress]:
        """Ray-cast form factors: the GPU hemicube would need a GL context of its own in the
        worker (the viewer's context belongs to the UI thread)."""
        method = "raycast" if scene.radiosity.form_factors == "hemicube" else None
        from shadelab.radiosity.solution import iter_radiosity

        return iter_radiosity(scene, size, form_factors=method)

    def viewport_job(self, scene: Scene, size=None, step_shots: int = 0) -> Iterator[Progress]:
        return pipeline_radiosity(scene, size, step_shots)


register(RadiosityPipeline())


def radiosity_key(scene: Scene) -> str:
    """What the patches and form factors depend on: geometry and meshing, not materials."""
    s = scene.radiosity
    objects = [(o.shape, o.material, o.path, o.radius, o.minor_radius, o.height, o.extents,
                o.size, tuple(map(tuple, o.vertices)), o.subdivisions, o.sections, o.segments,
                o.translate, o.rotate, o.scale) for o in scene.objects]
    return repr((objects, scene.base_dir, s.patches, ff_method(scene), s.hemicube_resolution))


def ff_method(scene: Scene) -> str:
    """The form-factor method the viewer's job asks for: the scene's. "hemicube" runs on a GL
    context of the job's own (:func:`_hemicube_backend`), ray-cast only where none can be made
    (the job's ``stats["form_factors"]`` says which ran)."""
    return scene.radiosity.form_factors


def _hemicube_backend() -> tuple[object, object, str]:
    """(hemicube factory for :class:`FormFactors`, release callback, "" or why not).

    The worker process's jobs run in its main thread and share its headless context (kept
    between jobs, as the form factors are); a job in a thread of the viewer (step mode) gets a
    context of its own, released when the job ends (a GL context is current in one thread)."""
    import threading
    from functools import partial

    try:
        from shadelab.gl.context import create_headless_context, headless_context
        from shadelab.raster.hemicube import Hemicube  # GL only in the job, only when asked

        if threading.current_thread() is threading.main_thread():
            return partial(Hemicube, ctx=headless_context()), None, ""
        ctx = create_headless_context()
    except Exception as exc:   # no GL for the job: ray-cast rows, said in the stats
        return None, None, str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    made = []

    def factory(*args, **kwargs):
        made.append(Hemicube(*args, ctx=ctx, **kwargs))
        return made[-1]

    def release():
        for cube in made:
            cube.release()
        ctx.release()

    return factory, release, ""


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
        rho[mask] = reflectance(material)
        emission[mask] = material.emission
    return rho, emission


@dataclass
class _Cached:
    """What the worker keeps of one geometry between jobs (``_RADIOSITY_CACHE``)."""

    patches: object
    rows: dict                 # patch -> its form-factor row, every row computed so far
    token: str
    ff: object = None          # the FormFactors engine, when it may outlive the job
    method: str = ""
    plan: object = None        # the display's geometry (radiosity.display.DisplayPlan)


def hemicube_batch(resolution: int) -> int:
    """Rows one hemicube atlas renders at once (:class:`shadelab.raster.hemicube.Hemicube`)."""
    res = max(2, int(resolution) // 2 * 2)
    return max(1, min(32, 4096 // res))


def pipeline_radiosity(scene: Scene, size: tuple[int, int] | None = None,
                       step_shots: int = 0) -> Iterator[Progress]:
    """Radiosity shot by shot; ``stats``: display ``soup``, ``shooter`` (4, 3) corners and
    ``shooter_index``, the patches' display radiosity ``B`` (N, 3) and the ``ambient``
    estimate, ``history``, ``patches``, ``form_factors`` (the method that ran),
    ``form_factors_reused``, the form factors' ``ff_token`` and ``ff_rows`` (indices, rows:
    the rows of F computed since the last Progress; every known row in the first), so the
    Hemicube & F window shows the very rows the solver used. ``step_shots`` > 0 yields after
    every that many shots (the step button). ``radiosity.ambient`` false: the display shows the
    light shot so far only."""
    from shadelab.radiosity import display
    from shadelab.radiosity.formfactors import FormFactors
    from shadelab.radiosity.patches import check_count
    from shadelab.radiosity.solution import base_patches, check_scene, solver_steps

    settings = scene.radiosity
    check_count(settings.patches, "radiosity.patches")
    check_scene(scene)
    start = time.perf_counter()
    key = radiosity_key(scene)
    cached = _RADIOSITY_CACHE.get(key)
    reused = cached is not None
    if cached is None:
        yield Progress(None, 0.0, "meshing", {"unit": "patches"})
        # uniform, whatever radiosity.meshing says: the Hemicube & F window (ui/) indexes
        # the same uniform grid by the shooter's number
        patches = base_patches(scene, settings.patches, "uniform")
        cached = _Cached(patches, {}, f"ff-{time.time_ns()}")
        _RADIOSITY_CACHE.clear()  # one geometry at a time: the rows can be large
        _RADIOSITY_CACHE[key] = cached
    patches, rows = cached.patches, cached.rows
    release = None
    if cached.ff is not None:
        ff, method, note = cached.ff, cached.method, ""
    else:
        method, hemicube, note = settings.form_factors, None, ""
        if method == "hemicube":
            hemicube, release, note = _hemicube_backend()
            method = method if hemicube is not None else "raycast"
        ff = FormFactors(patches, method, settings.hemicube_resolution, hemicube=hemicube)
        if release is None:
            cached.ff, cached.method = ff, method
    if cached.plan is None:
        cached.plan = display.DisplayPlan(patches)
    try:
        yield from _shoot(scene, patches, ff, method, rows, cached.token, reused, note, start,
                          step_shots, cached.plan, solver_steps)
    finally:
        if release is not None:
            release()


def _shoot(scene, patches, ff, method, rows, token, reused, note, start, step_shots, plan,
           solver_steps) -> Iterator[Progress]:
    settings = scene.radiosity
    rho, emission = _reflectance(scene, patches)
    n = len(patches)
    label = method + (f" {settings.hemicube_resolution}x{settings.hemicube_resolution}"
                      if method == "hemicube" else "")
    base = {"patches": n, "form_factors": method, "form_factors_label": label,
            "solver": settings.solver, "form_factors_reused": reused, "ff_token": token,
            "unit": "patches", "meshing_s": time.perf_counter() - start}
    if note:
        base["form_factors_note"] = f"hemicube asked, ray-cast used: no GL context ({note})"
    shooter = [-1]
    fresh = list(rows)                   # the rows the next Progress sends
    batch = hemicube_batch(settings.hemicube_resolution) if method == "hemicube" else 1
    areas = patches.areas
    shot = np.zeros_like(emission)       # what each patch has shot (its B when it shot)
    latest: list = [None]                # the solver's B (updated in place by each shot)

    def row(i: int) -> np.ndarray:
        shooter[0] = i
        if i not in rows:
            todo = [i]
            if batch > 1:   # the likeliest next shooters share the atlas (one read-back)
                B = latest[0] if latest[0] is not None else math.pi * emission
                energy = ((B - shot) * areas[:, None]).sum(axis=1)
                known = np.fromiter(rows, np.int64, len(rows))
                energy[known] = -np.inf
                energy[i] = -np.inf
                order = np.argsort(-energy)[:batch - 1]
                todo += [int(j) for j in order if energy[j] > 0.0]
            for j, values in zip(todo, ff.compute_rows(np.asarray(todo, np.int64)),
                                 strict=True):
                rows[j] = values
                fresh.append(j)
        shot[i] = latest[0][i] if latest[0] is not None else math.pi * emission[i]
        return rows[i]

    # no form factor known yet; not shot by shot (step mode: each press shoots one real shot)
    if settings.solver == "progressive" and not rows and step_shots <= 0:
        yield _first_shot(scene, patches, ff, method, rho, emission, base, start, plan,
                          rows, fresh)
    # the same driver as run(): right-hand side with the lights' first shot, form factors,
    # solver; only the streaming below differs (form factors here may come from the cache)
    steps = yield from solver_steps(scene, patches, ff, settings.solver, base, (0.0, 0.05),
                                    rho=rho, emission=emission, row=row)
    if settings.solver != "progressive":   # a gathering solver computed all of F
        for i in range(n):
            if i not in rows:
                rows[i] = ff.row(i)
                fresh.append(i)
    base.pop("form_factors_s", None)
    history = {"iteration": [], "residual": [], "unshot": [], "time_s": []}
    last, last_yield, since = None, 0.0, 0

    def progress(final: bool) -> Progress:
        sent = sorted(set(fresh))
        fresh.clear()
        values = np.stack([rows[i] for i in sent]) if sent else np.zeros((0, n))
        return _radiosity_progress(patches, rho, last, shooter[0], history, base, start,
                                   plan, len(rows), final, settings,
                                   (np.asarray(sent, np.int64), values))

    for last in steps:
        latest[0] = last.B
        history["iteration"].append(last.iteration)
        history["residual"].append(float(last.residual))
        history["unshot"].append(float(last.unshot))
        history["time_s"].append(time.perf_counter() - start)
        since += 1
        now = time.perf_counter()
        if step_shots > 0 and since < step_shots:
            continue
        if step_shots <= 0 and now - last_yield < RADIOSITY_CHUNK_S and last.iteration > 1:
            continue
        since, last_yield = 0, now
        yield progress(final=False)
    if last is None:
        return
    yield progress(final=True)


def _first_shot(scene, patches, ff, method, rho, emission, base, start, plan, rows,
                fresh) -> Progress:
    """Progressive refinement's first picture before the matrix exists (Cohen et al. 1988, as
    :func:`shadelab.radiosity.solution.iter_radiosity` shows it): the patch with the most
    power shot through its own row, one hemicube (the matrix's own row, kept and sent to the
    Hemicube & F window) or a ray-cast row integrated over it (a separate engine: the solve
    reads only the reciprocal matrix). The lesson's first lit image then waits for one row,
    not for all of F (Cornell, 402 patches: the matrix takes ~1.3 s)."""
    from shadelab.radiosity.formfactors import FormFactors
    from shadelab.radiosity.solution import sources
    from shadelab.radiosity.solvers import run_solver

    settings = scene.radiosity
    E = sources(scene, patches, stats=base, rho=rho, emission=emission)
    i = int(np.argmax((E * patches.areas[:, None]).sum(axis=1)))
    if method == "hemicube":
        f = rows[i] = ff.compute_rows(np.array([i], np.int64))[0]
        fresh.append(i)
    else:
        f = FormFactors(patches, method, settings.hemicube_resolution).row(i)
    first = next(run_solver("progressive", None, rho, E, 1, 0.0, row=lambda _: f,
                            areas=patches.areas))
    history = {"iteration": [1], "residual": [float(first.residual)],
               "unshot": [float(first.unshot)], "time_s": [time.perf_counter() - start]}
    sent = sorted(set(fresh))
    fresh.clear()
    values = np.stack([rows[j] for j in sent]) if sent else np.zeros((0, len(patches)))
    progress = _radiosity_progress(patches, rho, first, i, history, base, start, plan,
                                   len(rows), False, settings,
                                   (np.asarray(sent, np.int64), values))
    progress.stats["preview"] = True   # the solve starts again from E once F is known
    return progress


def _radiosity_progress(patches, rho, step, shooter, history, base, start, plan,
                        rows_known: int, final: bool, settings, ff_rows) -> Progress:
    B = step.display_B(rho) if settings.ambient else step.B
    meshes = plan.meshes(B / math.pi)
    value = step.unshot if np.isnan(step.residual) else step.residual
    tol = max(settings.tolerance, 1e-12)
    fraction = 1.0 if final or not value > tol else \
        min(0.99, math.log(max(value, 1e-300)) / math.log(tol)) if value < 1.0 else 0.0
    what = (f"shot {step.iteration}, unshot {step.unshot:.2e}" if np.isnan(step.residual)
            else f"iteration {step.iteration}, residual {step.residual:.2e}")
    stats = dict(base, soup=soup(meshes), history={k: list(v) for k, v in history.items()},
                 shots=step.iteration, elapsed_s=time.perf_counter() - start,
                 rows=rows_known, done=final, ff_rows=ff_rows,
                 ambient_shown=bool(settings.ambient),
                 # copies: the next shot updates the solver's arrays in place, and a job in
                 # a thread (step mode) hands this very Progress to the UI
                 B=np.array(B, np.float64), ambient=np.array(step.ambient, np.float64))
    if shooter >= 0:
        stats["shooter"] = np.asarray(patches.polygons[shooter], np.float32)
        stats["shooter_index"] = int(shooter)
    return Progress(None, max(fraction, 0.0), ("done: " if final else "") + what
                    + f" ({len(patches)} patches; {base['light']})", stats)
