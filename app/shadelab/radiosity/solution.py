"""Radiosity of a scene end to end: patches, form factors, a solver, and the display data.

``solve_scene`` runs it all and returns a :class:`RadiositySolution`; ``iter_radiosity`` is the
same job as a progressive generator of :class:`shadelab.progress.Progress` for the viewer's side
panel and the CLI's progress bar. Units (ARCHITECTURE.md §2): rho = kd * Od, E = pi * Le,
B = pi * L; images and ``display_meshes`` hold radiance L = B / pi.

This layer imports no GL: hemicube form factors need the GPU backend passed in, as
``hemicube=shadelab.raster.hemicube.Hemicube`` (:mod:`shadelab.raster.radiosity` binds it).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Iterator

import numpy as np

from shadelab.errors import ShadeLabError
from shadelab.progress import Progress
from shadelab.radiosity import display
from shadelab.radiosity.formfactors import FormFactors, check_backend
from shadelab.radiosity.patches import PatchSet, check_count, split_leaves, uniform_patches
from shadelab.radiosity.solvers import (
    SOLVERS,
    Step,
    check_solvable,
    new_history,
    record,
    run_solver,
)
from shadelab.scene.camera import primary_rays
from shadelab.scene.model import RADIOSITY_MESHINGS, Scene
from shadelab.shading.packing import reflectance

REFINE_SHARE = 0.85  # adaptive meshing starts from this share of the target count (Cornell,
#                     64x64 against the path tracer: 0.5 -> 5.3 % at 400 patches, 0.85 -> 4.6 %;
#                     uniform 4.6 %; at 800: 3.1 % against uniform 3.4 %)
REFINE_ROUNDS = 2  # solve-and-split rounds
REFINE_CONTRAST = 0.02  # split a leaf only where its corners differ by this share of the mean
CHUNK_SECONDS = 0.1  # work between two yields of iter_radiosity


@dataclass
class RadiositySolution:
    """A solved scene: patch radiosities and how they were obtained.

    Attributes
    ----------
    patches : the patch set
    B : (N, 3) radiosity per patch (W/m^2-like units: B = pi L), display B for progressive
    stats : patch count, methods, timings and the convergence history
    """

    scene: Scene
    patches: PatchSet
    B: np.ndarray
    stats: dict = field(default_factory=dict)
    form_factors: FormFactors | None = None  # the rows computed so far (heat map, teaching)

    def form_factor_matrix(self, hemicube=None) -> np.ndarray:
        """(N, N) F of this solution's patches (computed now where rows are missing;
        ``hemicube``: the GPU backend, needed only for a hemicube solution without rows)."""
        if self.form_factors is None:
            self.form_factors = FormFactors(self.patches, self.stats.get("form_factors",
                                                                         "raycast"),
                                            hemicube=hemicube)
        return self.form_factors.matrix()

    @property
    def radiance(self) -> np.ndarray:
        """(N, 3) patch radiance L = B / pi."""
        return self.B / math.pi

    def display_meshes(self, conforming: bool = True) -> list[display.Mesh]:
        """(vertices (V,3), faces (F,3), vertex_radiance (V,3)) per surface, world space.

        A clustered mesh is drawn as its own triangles, each vertex with the radiance of the
        clustered vertex it merged into (:func:`clustered_display`): its silhouette is the
        raster's, pixel for pixel, and its shading the clusters' radiosity."""
        meshes = display.display_meshes(self.patches, self.radiance, conforming)
        return clustered_display(self.patches, self.radiance, meshes)

    def image(self, size: tuple[int, int], conforming: bool = True,
              supersample: int = 1) -> np.ndarray:
        """CPU image (H, W, 3) float32 radiance from the scene camera (embreex primary rays,
        pixel centres like the rasterizer); GL-free, for the viewer's side panel.

        ``supersample`` = s averages s x s sub-pixel centres (a box filter, like the path
        tracer's jittered samples), for comparisons with it.
        """
        s = max(1, int(supersample))
        image = cpu_image(self.scene, self.display_meshes(conforming), (size[0] * s, size[1] * s))
        if s == 1:
            return image
        return image.reshape(size[1], s, size[0], s, 3).mean(axis=(1, 3)).astype(np.float32)


def clustered_display(patches: PatchSet, radiance: np.ndarray,
                      meshes: list[display.Mesh]) -> list[display.Mesh]:
    """``meshes`` (one per surface with patches, in surface order) with each clustered mesh
    replaced by its original triangles: a vertex takes the area-weighted radiance of the
    patches (clustered triangles) around the clustered vertex it merged into."""
    owners = [i for i, _ in enumerate(patches.surfaces) if np.any(patches.surface == i)]
    if len(owners) != len(meshes):
        return meshes
    out = list(meshes)
    for m, index in enumerate(owners):
        surface = patches.surfaces[index]
        if surface.kind != "mesh" or surface.original is None:
            continue
        vertices, faces, to_cluster = surface.original
        members = np.flatnonzero(patches.surface == index)
        tri = patches.tri[members]
        values = np.zeros((len(surface.vertices), 3))
        weight = np.zeros(len(surface.vertices))
        for corner in range(3):
            np.add.at(values, tri[:, corner], radiance[members] * patches.areas[members, None])
            np.add.at(weight, tri[:, corner], patches.areas[members])
        mean = (radiance[members] * patches.areas[members, None]).sum(axis=0) \
            / max(float(patches.areas[members].sum()), 1e-300)
        values = np.where(weight[:, None] > 0.0, values / np.maximum(weight, 1e-300)[:, None],
                          mean[None, :])
        out[m] = (vertices, faces, values[to_cluster])
    return out


# ---------------------------------------------------------------------- checks
def check_scene(scene: Scene) -> None:
    """Refuse a scene radiosity cannot light: nothing emits and no point, spot or directional
    light (other than a ``stand_in``) is on."""
    from shadelab.radiosity.direct import direct_lights

    used = {obj.material for obj in scene.objects}
    if direct_lights(scene):
        return
    if not any(max(scene.materials[m].emission) > 0.0 for m in used if m in scene.materials):
        raise ShadeLabError(f"{scene.name or 'scene'}: no object has a material with emission "
                            f"> 0 and no light is on, so radiosity has no light to spread (set "
                            f"materials.X.emission or add a light)")


def sources(scene: Scene, patches: PatchSet, stats: dict | None = None,
            rho: np.ndarray | None = None, emission: np.ndarray | None = None) -> np.ndarray:
    """(N, 3) the right-hand side E of B = E + rho F B: the emitters' pi * Le plus the
    lights' direct light reflected, rho * H (the first shot, :mod:`.direct`). ``stats``
    gets ``light_power`` (per light), ``emitted_power`` and the one-line ``light``.
    ``rho``, ``emission`` (N, 3): the current materials' (default: the patches' own)."""
    from shadelab.radiosity.direct import describe, direct_radiosity

    E_direct, power = direct_radiosity(scene, patches, rho=rho)
    E_emit = patches.E if emission is None else math.pi * np.asarray(emission, float)
    E = E_emit + E_direct
    if stats is not None:
        emitted = float((patches.areas[:, None] * E_emit).sum() / 3.0)
        stats.update(light_power=power, emitted_power=emitted, light=describe(power, emitted))
    return E


def precheck(scene: Scene, count: int, method: str = "raycast") -> None:
    """Fail fast, before any progress bar: no emitter, or reflectance >= 1 where the scene
    is closed enough that (I - rho F) B = E has no bounded solution."""
    check_scene(scene)
    used = {obj.material for obj in scene.objects}
    if all(max(reflectance(scene.materials[m])) < 1.0 for m in used):
        return  # row sums of rho F < 1: every solver converges
    patches = uniform_patches(scene, min(check_count(count), 200))
    F = FormFactors(patches, "raycast" if method == "hemicube" else method).matrix()
    check_solvable(F, patches.rho, lambda: _rho_names(scene, patches))


def _rho_names(scene: Scene, patches: PatchSet) -> str:
    names = sorted({s.material for s in patches.surfaces
                    if max(reflectance(scene.materials[s.material])) >= 1.0})
    return ", ".join(f"materials.{n}" for n in names) or "materials"


# ---------------------------------------------------------------------- meshing
MESHINGS = RADIOSITY_MESHINGS  # uniform, adaptive (solve-and-split rounds), discontinuity


def check_meshing(meshing: str) -> None:
    if meshing not in MESHINGS:
        raise ShadeLabError(f"meshing {meshing!r}: expected one of {', '.join(MESHINGS)}")


def resolve_meshing(scene: Scene, meshing: str | None, adaptive: bool = True) -> str:
    """The meshing a job uses: ``meshing``, else the scene's ``radiosity.meshing``.
    ``adaptive=False`` (``--uniform``, the benches, the studies) means a regular grid: it
    turns "adaptive" and an unnamed meshing into "uniform"."""
    if meshing is None:
        meshing = scene.radiosity.meshing if adaptive else "uniform"
    check_meshing(meshing)
    return "uniform" if meshing == "adaptive" and not adaptive else meshing


def base_patches(scene: Scene, count: int, meshing: str = "uniform") -> PatchSet:
    """The first mesh: a regular grid ("uniform", also the start of "adaptive"), or one
    refined along contact lines and shadow boundaries
    (:func:`shadelab.radiosity.meshing.discontinuity_patches`)."""
    check_meshing(meshing)
    if meshing == "discontinuity":
        from shadelab.radiosity.meshing import discontinuity_patches

        return discontinuity_patches(scene, count)
    return uniform_patches(scene, count)


def mesh_scene(scene: Scene, count: int, method: str = "raycast", adaptive: bool = True,
               resolution: int = 128, hemicube=None) -> PatchSet:
    """Patches for the scene: uniform, or refined where the radiosity changes fast.

    Adaptive meshing solves a coarser mesh (``REFINE_SHARE`` of ``count``), splits the leaves
    whose corner radiances differ most from their own (shadow edges, corners) and repeats;
    leaves in flat regions stay as they are, so the result may have fewer than ``count``.
    ``hemicube``: the GPU backend when ``method`` is "hemicube" (see :class:`FormFactors`).
    """
    count = check_count(count)
    check_backend(method, hemicube)
    if not adaptive or count < 8:
        return uniform_patches(scene, count)
    patches = uniform_patches(scene, max(1, int(count * REFINE_SHARE)))
    for round_ in range(REFINE_ROUNDS):
        budget = count if round_ == REFINE_ROUNDS - 1 else \
            len(patches) + (count - len(patches)) // 2
        splits = (budget - len(patches)) // 3
        if splits <= 0:
            break
        F = FormFactors(patches, method, resolution, hemicube=hemicube).matrix()
        check_solvable(F, patches.rho, lambda p=patches: _rho_names(scene, p))
        B = _solve_quick(F, patches, sources(scene, patches))
        chosen = _refine_candidates(patches, B / math.pi, splits)
        if len(chosen) == 0:
            break
        patches = split_leaves(scene, patches, chosen)
    patches.info["adaptive"] = True
    return patches


def _solve_quick(F: np.ndarray, patches: PatchSet, E: np.ndarray | None = None) -> np.ndarray:
    """B of (I - rho F) B = E (default E: the emitters' pi * Le alone)."""
    E = patches.E if E is None else E
    n = len(F)
    return np.stack([np.linalg.solve(np.eye(n) - patches.rho[:, c, None] * F, E[:, c])
                     for c in range(3)], axis=1)


def _refine_candidates(patches: PatchSet, radiance: np.ndarray, splits: int) -> np.ndarray:
    """Quad leaves to split: the largest corner-to-patch contrast, above a threshold."""
    luminance = radiance @ np.array([0.2126, 0.7152, 0.0722])
    lit = patches.emission.max(axis=1) == 0.0
    scale = max(float(np.average(luminance[lit], weights=patches.areas[lit]))
                if lit.any() else 1.0, 1e-300)
    meshes = display.display_meshes(patches, radiance, conforming=False)
    score = np.zeros(len(patches))
    mesh_of = [i for i, s in enumerate(patches.surfaces)
               if np.any(patches.surface == i)]
    for surface_index, (vertices, _, values) in zip(mesh_of, meshes, strict=True):
        surface = patches.surfaces[surface_index]
        if surface.kind != "quad":
            continue
        members = np.flatnonzero(patches.surface == surface_index)
        y = values @ np.array([0.2126, 0.7152, 0.0722])
        for k in members:
            corners = patches.polygons[k]
            near = np.linalg.norm(vertices[None, :, :] - corners[:, None, :], axis=2)
            ids = np.argmin(near, axis=1)
            score[k] = np.abs(y[ids] - luminance[k]).max() / scale * patches.areas[k]
    splittable = (patches.rects[:, 0] >= 0) & ((patches.rects[:, 2] - patches.rects[:, 0]) > 1)
    score[~splittable | ~lit] = 0.0
    if splits <= 0:
        return np.zeros(0, np.int64)
    order = np.argsort(-score)
    mean_area = float(patches.areas.mean())
    return order[:splits][score[order[:splits]] > REFINE_CONTRAST * mean_area]


# ---------------------------------------------------------------------- solving
def _settings(scene: Scene, patches, form_factors, solver):
    settings = scene.radiosity
    patches = settings.patches if patches is None else patches
    form_factors = form_factors or settings.form_factors
    solver = solver or settings.solver
    if solver not in SOLVERS:
        raise ShadeLabError(f"--solver '{solver}': expected one of {', '.join(SOLVERS)}")
    return check_count(patches), form_factors, solver


def iter_radiosity(scene: Scene, size: tuple[int, int] | None = None, patches: int | None = None,
                   form_factors: str | None = None, solver: str | None = None,
                   adaptive: bool = True, resolution: int | None = None,
                   image_every: float = 0.25, hemicube=None,
                   meshing: str | None = None) -> Iterator[Progress]:
    """Radiosity as a progressive job: yields :class:`Progress` after each chunk of work.

    With ``adaptive`` the job solves a coarse uniform mesh first (``REFINE_SHARE`` of the
    target), splits the leaves where radiosity changes fast, and solves again, up to
    ``REFINE_ROUNDS`` times: each stage shows a complete picture, and progressive refinement
    yields a lit image right after its first shot. ``image`` is a CPU rendering of the
    current solution from the scene camera (``size`` = (W, H); None: no images). ``stats``
    holds ``patches``, ``form_factors``, ``solver``, ``stage``, timings and ``history``
    (iteration, residual, unshot, time_s of the current stage's solver), and, at the end,
    ``solution`` (a :class:`RadiositySolution`). Close the generator to cancel.
    ``hemicube``: the GPU backend, required when the method is "hemicube"
    (``shadelab.raster.hemicube.Hemicube``; see :class:`FormFactors`).
    ``meshing``: "uniform" (a regular grid), "adaptive" (a grid refined in solve-and-split
    rounds, as above) or "discontinuity" (refined along shadow boundaries before any solve,
    hidden cells dropped: :mod:`.meshing`); None: the scene's ``radiosity.meshing``.
    ``adaptive=False`` turns "adaptive" and None into "uniform" (the refinement rounds run
    only for "adaptive"; see :func:`resolve_meshing`).
    """
    count, method, solver = _settings(scene, patches, form_factors, solver)
    meshing = resolve_meshing(scene, meshing, adaptive)
    check_backend(method, hemicube)
    resolution = resolution or scene.radiosity.hemicube_resolution
    precheck(scene, count, method)
    start = time.perf_counter()
    stats = {"form_factors": method, "solver": solver, "target_patches": count}
    yield Progress(None, 0.0, "meshing", dict(stats))
    refine = meshing == "adaptive" and count >= 8
    mesh = base_patches(scene, max(1, int(count * REFINE_SHARE)) if refine else count,
                        "uniform" if meshing == "adaptive" else meshing)
    stats["meshing"] = meshing
    stages = REFINE_ROUNDS + 1 if refine else 1
    for stage in range(stages):
        stats.update(stage=f"{stage + 1}/{stages}", patches=len(mesh),
                     meshing_s=time.perf_counter() - start)
        band = (stage / stages, (stage + 1) / stages)
        B = yield from _solve_stage(scene, mesh, method, solver, resolution, size, image_every,
                                    stats, band, start, final=stage == stages - 1,
                                    hemicube=hemicube)
        if stage == stages - 1:
            break
        budget = count if stage == stages - 2 else len(mesh) + (count - len(mesh)) // 2
        splits = (budget - len(mesh)) // 3
        chosen = _refine_candidates(mesh, B / math.pi, splits) if splits > 0 else []
        if len(chosen) == 0:  # flat everywhere: the coarse mesh is the answer
            stats["refined_out"] = True
            yield from _finish(scene, mesh, B, stats, size, start)
            return
        mesh = split_leaves(scene, mesh, chosen)


def solver_steps(scene: Scene, mesh: PatchSet, ff: FormFactors, solver: str, stats: dict,
                 band: tuple[float, float] = (0.0, 1.0), rho: np.ndarray | None = None,
                 emission: np.ndarray | None = None, row=None):
    """The one driver of both ways to watch radiosity (``iter_radiosity`` and the viewer's
    :func:`shadelab.pipelines.radiosity.pipeline_radiosity`): the right-hand side E (emitters
    plus the lights' first shot, :func:`sources`), the form factors (yielding progress in the
    first 60 % of ``band``) and the solvability check; returns the solver's :class:`Step`
    iterator. Only how the steps are streamed differs.

    Every solver reads the one matrix: ray-cast and analytic factors are computed once per
    pair from the smaller patch and made reciprocal (:meth:`FormFactors.matrix`), so
    progressive refinement shoots through the same F that Gauss-Seidel gathers with -- a row
    on demand would integrate over the shooter (often the large emitter), cost twice the
    pairs and solve a slightly different system (Cornell, 1029 patches: 6.4 s against
    1.9 s). ``rho``, ``emission``: the current materials (default: the mesh's own); ``row``:
    the progressive solver's row function (default ``ff.row``, the matrix's rows once it is
    computed; the viewer wraps it to learn the shooter)."""
    settings = scene.radiosity
    rho = mesh.rho if rho is None else rho
    E = sources(scene, mesh, stats=stats, rho=rho, emission=emission)
    t0 = time.perf_counter()
    span = band[1] - band[0]
    for done in ff.iter_matrix():
        yield Progress(None, band[0] + 0.6 * span * done,
                       f"form factors {int(done * 100)}% ({len(mesh)} patches)", dict(stats))
    F = ff.matrix()
    stats["form_factors_s"] = time.perf_counter() - t0
    check_solvable(F, rho, lambda: _rho_names(scene, mesh))
    if solver == "progressive":
        return run_solver(solver, None, rho, E, settings.iterations, settings.tolerance,
                          row=row or ff.row, areas=mesh.areas)
    return run_solver(solver, F, rho, E, settings.iterations, settings.tolerance,
                      areas=mesh.areas)


def _solve_stage(scene, mesh, method, solver, resolution, size, image_every, stats, band,
                 start, final, hemicube=None):
    """Form factors and a solve of one mesh, yielding progress; returns the display B."""
    settings = scene.radiosity
    ff = FormFactors(mesh, method, resolution, hemicube=hemicube)
    history = new_history()
    stats["history"] = history
    span = band[1] - band[0]
    if solver == "progressive" and size is not None and "first_image_s" not in stats:
        yield _first_shot_preview(scene, mesh, ff, stats, size, start, band[0])
    steps = yield from solver_steps(scene, mesh, ff, solver, stats, band)
    last = yield from _drive(scene, mesh, steps, history, stats, size, image_every, start,
                             (band[0] + 0.6 * span, band[1]))
    stats["solve_s"] = last.seconds
    value = last.unshot if np.isnan(last.residual) else last.residual
    stats["converged"] = bool(value <= settings.tolerance) or solver == "direct"
    B = last.display_B(mesh.rho).copy()
    stats["_form_factors"] = ff
    if final:
        yield from _finish(scene, mesh, B, stats, size, start)
    return B


def _first_shot_preview(scene, mesh, ff, stats, size, start, fraction) -> Progress:
    """Progressive refinement's first picture before the matrix exists (Cohen et al. 1988):
    the brightest patch shot through one row integrated over it (:meth:`FormFactors.row`, a
    separate engine, so the solve still reads only the reciprocal matrix; a hemicube row is
    the matrix's own). Only where images are asked for (the viewer, the first-image bench)."""
    E = sources(scene, mesh)
    i = int(np.argmax((E * mesh.areas[:, None]).sum(axis=1)))
    rows = ff if ff.method == "hemicube" else FormFactors(mesh, ff.method, ff.resolution)
    f = rows.row(i)
    first = next(run_solver("progressive", None, mesh.rho, E, 1, 0.0, row=lambda _: f,
                            areas=mesh.areas))
    solution = RadiositySolution(scene, mesh, first.display_B(mesh.rho), dict(stats))
    image = solution.image(size)
    stats["first_image_s"] = time.perf_counter() - start
    return Progress(image, fraction, f"first shot, a preview ({len(mesh)} patches)",
                    dict(stats))


def _finish(scene, mesh, B, stats, size, start) -> Iterator[Progress]:
    stats["patches"] = len(mesh)
    stats["total_s"] = time.perf_counter() - start
    ff = stats.pop("_form_factors", None)
    solution = RadiositySolution(scene, mesh, B, stats, ff)
    stats["solution"] = solution
    image = solution.image(size) if size is not None else None
    yield Progress(image, 1.0, f"done: {len(mesh)} patches; {stats.get('light', '')}", stats)


def _drive(scene, mesh, steps, history, stats, size, image_every, start, band):
    """Run solver steps in chunks, yielding progress (and images) between them; returns the
    last step."""
    last: Step | None = None
    last_image = -1e9
    chunk_start = time.perf_counter()
    first = True
    for last in steps:
        record(history, last)
        if first and "first_shot_s" not in stats and np.isnan(last.residual):
            stats["first_shot_s"] = time.perf_counter() - start
        now = time.perf_counter()
        if now - chunk_start < CHUNK_SECONDS and not first:
            continue
        chunk_start = now
        fraction = _fraction(last, scene)
        image = None
        if size is not None and (now - last_image >= image_every or first):
            solution = RadiositySolution(scene, mesh, last.display_B(mesh.rho), dict(stats))
            image = solution.image(size)
            last_image = time.perf_counter()
            if "first_image_s" not in stats:
                stats["first_image_s"] = last_image - start
        first = False
        message = (f"shot {last.iteration}, unshot {last.unshot:.2e}" if np.isnan(last.residual)
                   else f"iteration {last.iteration}, residual {last.residual:.2e}")
        yield Progress(image, band[0] + (band[1] - band[0]) * 0.99 * fraction,
                       f"{message} ({len(mesh)} patches)", dict(stats))
    if last is None:
        raise ShadeLabError("radiosity: the solver produced no result")
    return last


def _fraction(step: Step, scene: Scene) -> float:
    """How far the solver is: log-scale progress of the residual (or unshot) to the tolerance."""
    value = step.unshot if np.isnan(step.residual) else step.residual
    tol = max(scene.radiosity.tolerance, 1e-12)
    if not value > 0.0:
        return 1.0
    return float(np.clip(math.log(max(value, tol)) / math.log(tol), 0.0, 1.0)) \
        if value < 1.0 else 0.0


def solve_scene(scene: Scene, patches: int | None = None, form_factors: str | None = None,
                solver: str | None = None, adaptive: bool = True,
                resolution: int | None = None, hemicube=None,
                meshing: str | None = None) -> RadiositySolution:
    """Mesh, compute form factors and solve; returns the solution (no images).
    ``hemicube``: the GPU backend for hemicube form factors, ``meshing`` the first mesh
    (see :func:`iter_radiosity`)."""
    job = iter_radiosity(scene, None, patches, form_factors, solver, adaptive, resolution,
                         hemicube=hemicube, meshing=meshing)
    *_, last = job
    return last.stats["solution"]


# ---------------------------------------------------------------------- CPU image
def cpu_image(scene: Scene, meshes: list[display.Mesh], size: tuple[int, int]) -> np.ndarray:
    """Gouraud image of per-vertex radiance meshes by ray casting (embreex), (H, W, 3) float32."""
    import embreex.mesh_construction as mc
    import embreex.rtcore_scene as rs

    width, height = size
    vertices = np.concatenate([m[0] for m in meshes])
    offsets = np.cumsum([0] + [len(m[0]) for m in meshes[:-1]])
    faces = np.concatenate([m[1] + o for m, o in zip(meshes, offsets, strict=True)])
    values = np.concatenate([m[2] for m in meshes])
    tri = vertices[faces]
    keep = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1) > 0
    faces, tri = faces[keep], tri[keep]
    rt = rs.EmbreeScene()
    mc.TriangleMesh(rt, np.ascontiguousarray(tri, np.float32))
    origins, dirs = primary_rays(scene.camera, width, height)
    hit = rt.run(origins.reshape(-1, 3).astype(np.float32), dirs.reshape(-1, 3).astype(np.float32),
                 output=1)
    prim = hit["primID"]
    u, v = hit["u"].astype(np.float64), hit["v"].astype(np.float64)
    # Pixels before the near plane are clipped by the rasterizer: do the same
    forward = np.asarray(scene.camera.target, float) - np.asarray(scene.camera.eye, float)
    forward /= np.linalg.norm(forward)
    depth = hit["tfar"] * (dirs.reshape(-1, 3) @ forward)
    ok = (prim >= 0) & (depth >= scene.camera.near)
    image = np.empty((width * height, 3))
    image[:] = scene.render.background
    f = faces[prim[ok]]
    image[ok] = ((1 - u[ok] - v[ok])[:, None] * values[f[:, 0]] + u[ok][:, None] * values[f[:, 1]]
                 + v[ok][:, None] * values[f[:, 2]])
    return image.reshape(height, width, 3).astype(np.float32)
