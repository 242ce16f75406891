"""``shadelab raytrace`` (Whitted) and ``shadelab pathtrace`` (reference GI)."""

from __future__ import annotations

import argparse

from shadelab import limits
from shadelab.errors import ShadeLabError
from shadelab.imageio import add_scene_arguments, check_outputs, parse_size, save_outputs
from shadelab.raytrace import BACKENDS
from shadelab.scene.preset import load_preset

MAX_DEPTH = 64


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("raytrace", help="Whitted recursive ray tracing of a preset (CPU)")
    add_scene_arguments(p, default_size="512x512")
    p.add_argument("--depth", type=int, metavar="N", help="maximum recursion depth (>= 0)")
    p.add_argument("--spp", type=int, metavar="N", help="stratified samples per pixel (>= 1)")
    p.add_argument("--fresnel", action="store_true", default=None,
                   help="weight reflection/refraction by Fresnel's equations")
    p.add_argument("--backend", choices=BACKENDS, default="auto",
                   help="ray casting: embree (embreex) or the numba BVH")
    p.add_argument("--error", type=float, metavar="BUDGET",
                   help="auto quality: the cheapest depth and spp within this relative MSE "
                        "(e.g. 0.01; see shadelab.studies.autoquality)")
    p.add_argument("--workers", type=int, default=1, metavar="N",
                   help="processes tracing tiles in parallel (default 1; 2 uses both cores "
                        "of an idle machine, each worker takes a second or two to start)")
    p.set_defaults(run=run_raytrace)

    p = sub.add_parser("pathtrace", help="Monte Carlo path tracing (reference radiance)")
    add_scene_arguments(p, default_size="256x256")
    p.add_argument("--spp", type=int, default=64, metavar="N", help="samples per pixel (>= 1)")
    p.add_argument("--seed", type=int, default=0, help="random seed")
    p.add_argument("--backend", choices=BACKENDS, default="auto",
                   help="ray casting: embree (embreex) or the numba BVH")
    p.add_argument("--workers", type=int, default=1, metavar="N",
                   help="processes tracing tiles in parallel (default 1)")
    p.set_defaults(run=run_pathtrace)


def _check_counts(depth: int | None, spp: int | None, workers: int | None = None) -> None:
    if workers is not None and not 1 <= workers <= 64:
        raise ShadeLabError(f"--workers {workers}: expected an integer in [1, 64]")
    if depth is not None and not 0 <= depth <= MAX_DEPTH:
        raise ShadeLabError(f"--depth {depth}: expected an integer in [0, {MAX_DEPTH}]")
    if spp is not None and spp < 1:
        raise ShadeLabError(f"--spp {spp}: expected an integer >= 1")


MAX_SEED = 2**63 - 1


def _check_seed(seed: int) -> None:
    if not 0 <= seed <= MAX_SEED:
        raise ShadeLabError(f"--seed {seed}: expected an integer in [0, 2**63 - 1]")


def _check_scene(scene, preset: str) -> None:
    if not scene.objects:
        raise ShadeLabError(f"{preset}: objects: the scene is empty (expected at least one)")


def _note_if_nothing_visible(stats: dict) -> None:
    if stats.get("primary_hits", 1) == 0:
        from shadelab.progress import note

        note("no object is visible from the camera; the image is the background")


def run_raytrace(args: argparse.Namespace) -> int:
    size = parse_size(args.size)
    _check_counts(args.depth, args.spp, args.workers)
    scene = load_preset(args.preset, list(args.set))
    _check_scene(scene, args.preset)
    limits.check_pixels(size)
    if getattr(args, "error", None) is None:
        spp = args.spp or scene.raytrace.spp
        limits.check_samples(size, spp, "--spp" if args.spp else "raytrace.spp")
    if not scene.active_lights():
        raise ShadeLabError(f"{args.preset}: lights: the ray tracer needs at least one "
                            "enabled light")
    if getattr(args, "error", None) is not None:
        from shadelab.studies.autoquality import check_budget

        check_budget(args.error)
    check_outputs(args, scene)
    from shadelab import pipelines
    from shadelab.progress import run_to_end

    if getattr(args, "error", None) is not None:
        from shadelab.studies.raytrace_study import auto_raytrace

        args.depth, args.spp, line = auto_raytrace(scene, size, args.error)
        print(line)

    job = pipelines.get("raytrace").run(scene, size, args.depth, args.spp, args.fresnel,
                                        args.backend, workers=args.workers)
    last = run_to_end(job, desc="raytrace")
    save_outputs(args, last.image, scene.render.exposure)
    _note_if_nothing_visible(last.stats)
    s = last.stats
    print(f"wrote {args.output} ({size[0]}x{size[1]}, {s['rays']} rays, "
          f"{s['rays_per_s'] / 1e6:.2f} Mrays/s, depth reached {s['depth_reached']}, "
          f"{s['backend']})")
    return 0


def run_pathtrace(args: argparse.Namespace) -> int:
    size = parse_size(args.size)
    _check_counts(None, args.spp, args.workers)
    _check_seed(args.seed)
    scene = load_preset(args.preset, list(args.set))
    _check_scene(scene, args.preset)
    limits.check_pixels(size)
    limits.check_samples(size, args.spp)
    from shadelab import pipelines

    pathtrace = pipelines.get("pathtrace")
    pathtrace.check(scene, args.preset)
    check_outputs(args, scene)
    from shadelab.progress import run_to_end

    last = run_to_end(pathtrace.run(scene, size, args.spp, args.seed, args.backend,
                                    workers=args.workers), desc="pathtrace")
    save_outputs(args, last.image, scene.render.exposure)
    _note_if_nothing_visible(last.stats)
    s = last.stats
    print(f"wrote {args.output} ({size[0]}x{size[1]}, {args.spp} spp, "
          f"{s['samples_per_s'] / 1e3:.1f} k samples/s, {s['backend']})")
    return 0
