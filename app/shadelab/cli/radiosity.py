"""``shadelab radiosity``: solve a preset's radiosity and write the Gouraud-shaded GL image."""

from __future__ import annotations

import argparse

from shadelab import limits
from shadelab.imageio import add_scene_arguments, check_outputs, parse_size, save_outputs
from shadelab.progress import run_to_end
from shadelab.scene.model import RADIOSITY_MESHINGS as MESHINGS
from shadelab.scene.model import RADIOSITY_SOLVERS as SOLVERS
from shadelab.scene.preset import load_preset


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("radiosity", help="radiosity of a preset: patches, form factors, a "
                                         "solver, and the Gouraud-shaded image")
    add_scene_arguments(p, default_size="512x512")
    p.add_argument("--patches", type=int, metavar="N",
                   help="target patch count (default: the preset's radiosity.patches)")
    p.add_argument("--form-factors", choices=("hemicube", "raycast"),
                   help="GPU hemicube or ray-cast (Wallace 1989) form factors")
    p.add_argument("--solver", choices=SOLVERS, help="direct, Jacobi, Gauss-Seidel or "
                                                     "progressive refinement")
    p.add_argument("--meshing", choices=MESHINGS,
                   help="uniform grid, adaptive (solve-and-split rounds) or discontinuity "
                        "(shadow boundaries split, hidden cells dropped; default: the "
                        "preset's radiosity.meshing)")
    p.add_argument("--uniform", action="store_true",
                   help="regular patches only (same as --meshing uniform)")
    p.add_argument("--error", type=float, metavar="BUDGET",
                   help="auto quality: the fewest uniform patches (and hemicube pixels) within "
                        "this relative MSE (e.g. 0.01; see shadelab.studies.autoquality)")
    p.set_defaults(run=run_radiosity)


def run_radiosity(args: argparse.Namespace) -> int:
    size = parse_size(args.size)
    if args.patches is not None:
        from shadelab.radiosity.patches import check_count  # trimesh: only when the command runs

        check_count(args.patches)
    scene = load_preset(args.preset, args.set)
    if getattr(args, "meshing", None):
        scene.radiosity.meshing = args.meshing
    if args.uniform:
        scene.radiosity.meshing = "uniform"
    limits.check_pixels(size, bytes_per_pixel=64)
    limits.check_patches(args.patches or scene.radiosity.patches,
                         "--patches" if args.patches else "radiosity.patches")
    if getattr(args, "error", None) is not None:
        from shadelab.studies.autoquality import check_budget

        check_budget(args.error)
    check_outputs(args, scene)
    from shadelab.radiosity.solution import precheck

    if getattr(args, "error", None) is not None:
        from shadelab.studies.radiosity_study import auto_radiosity

        precheck(scene, scene.radiosity.patches,
                 args.form_factors or scene.radiosity.form_factors)
        args.patches, resolution, line = auto_radiosity(scene, size, args.error,
                                                        args.form_factors)
        scene.radiosity.hemicube_resolution = resolution
        args.uniform = True
        scene.radiosity.meshing = "uniform"
        print(line)

    from shadelab import pipelines

    radiosity = pipelines.get("radiosity")
    job = radiosity.run(scene, None, args.patches, args.form_factors, args.solver,
                        adaptive=not args.uniform, gpu=True)  # GPU hemicube available here
    last = run_to_end(job, desc="radiosity")
    solution = last.stats["solution"]
    image = radiosity.image(last, size)  # GL only once solved
    save_outputs(args, image, scene.render.exposure)
    stats = solution.stats
    print(f"wrote {args.output} ({size[0]}x{size[1]}): {stats['patches']} patches, "
          f"{stats['form_factors']} form factors, {stats['solver']} solver, "
          f"{len(stats['history']['iteration'])} iterations, {stats['total_s']:.2f} s"
          + ("" if stats["converged"] else " (not converged: raise radiosity.iterations)")
          + f"; {stats['light']}")
    return 0
