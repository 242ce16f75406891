"""``shadelab render``, ``shadelab presets`` and ``shadelab validate``."""

from __future__ import annotations

import argparse

from shadelab import limits
from shadelab.errors import ShadeLabError
from shadelab.imageio import (
    add_allow_large,
    add_scene_arguments,
    check_outputs,
    parse_size,
    save_outputs,
)
from shadelab.scene.model import SHADING_MODES, SPECULAR_MODELS
from shadelab.scene.preset import list_presets, load_preset, read_toml, resolve_preset


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("render", help="headless EGL raster render of a preset")
    add_scene_arguments(p)
    p.add_argument("--shading", choices=SHADING_MODES, help="override the preset's shading")
    p.add_argument("--specular", choices=SPECULAR_MODELS, help="phong (R.V)^n or blinn (N.H)^n")
    p.add_argument("--shadows", choices=("none", "volumes"), help="stencil shadow volumes")
    p.add_argument("--shadow-method", choices=("zfail", "zpass"), help="stencil counting")
    p.add_argument("--visibility", choices=("zbuffer", "painter"),
                   help="hidden surfaces: z-buffer or list priority (painter's algorithm)")
    p.add_argument("--show-volumes", action="store_true", help="draw shadow volumes, translucent")
    p.add_argument("--show-silhouettes", action="store_true", help="highlight silhouette edges")
    p.add_argument("--stencil-heatmap", action="store_true",
                   help="overlay the stencil count (render.heatmap_light) as a heat map")
    p.add_argument("--error", type=float, metavar="BUDGET",
                   help="auto quality: tessellate each sphere no finer than this relative MSE "
                        "needs (e.g. 0.01; see shadelab.studies.autoquality)")
    p.add_argument("--pipeline", metavar="NAME",
                   help="any pipeline of shadelab.pipelines (default raster: the GL z-buffer; "
                        "gouraud, phong, flat, painter, raytrace, pathtrace, radiosity, ...), "
                        "with its default settings")
    p.add_argument("-v", "--verbose", action="store_true",
                   help="print the OpenGL context used (egl or native, SHADELAB_GL) and its "
                        "renderer")
    p.set_defaults(run=run_render)

    p = sub.add_parser("presets", help="list the presets shipped with ShadeLab")
    p.set_defaults(run=run_presets)

    p = sub.add_parser("validate", help="check presets; exit 2 on the first bad one")
    p.add_argument("presets", nargs="+", metavar="PRESET")
    add_allow_large(p)
    p.set_defaults(run=run_validate)


RASTER_FLAGS = ("shading", "specular", "shadows", "shadow_method", "visibility", "error")


def run_render(args: argparse.Namespace) -> int:
    size = parse_size(args.size)
    name = getattr(args, "pipeline", None)
    if name and name != "raster":
        from shadelab import pipelines

        pipeline = pipelines.get(name, "--pipeline")
        if pipeline.raster is None:
            return run_pipeline(args, pipeline, size)
        shading, visibility = pipeline.raster
        if name != "painter":
            if args.shading and args.shading != shading:
                raise ShadeLabError(f"--shading {args.shading}: the {name} pipeline shades "
                                    f"{shading}")
            args.shading = shading
        args.visibility = visibility
    overrides = list(args.set)
    for flag, key in (("shadows", "render.shadows"), ("shadow_method", "render.shadow_method")):
        if getattr(args, flag, None):
            overrides.append(f"{key}={getattr(args, flag)}")
    if getattr(args, "visibility", None):
        overrides.append(f"render.visibility={args.visibility}")
    for flag in ("show_volumes", "show_silhouettes", "stencil_heatmap"):
        if getattr(args, flag, False):
            overrides.append(f"render.{flag}=true")
    scene = load_preset(args.preset, overrides)
    limits.check_pixels(size, bytes_per_pixel=64)
    if getattr(args, "error", None) is not None:
        from shadelab.studies.autoquality import check_budget

        check_budget(args.error)
    check_outputs(args, scene)
    from shadelab import pipelines  # GL (inside run) only once the input is known good

    if getattr(args, "error", None) is not None:
        from shadelab.studies.autoquality import auto_tessellate

        shading = args.shading or scene.render.shading
        for line in auto_tessellate(scene, shading, size, args.error, args.specular):
            print(line)

    *_, last = pipelines.get("raster").run(scene, size, args.shading, args.specular)
    image = last.image
    if getattr(args, "verbose", False):
        from shadelab.gl.context import context_info, headless_context

        gl = context_info(headless_context())
        print(f"gl: {gl['backend']}, {gl['renderer']}, OpenGL {gl['version']}")
    save_outputs(args, image, scene.render.exposure,
                 {"shading": args.shading or scene.render.shading})
    print(f"wrote {args.output} ({size[0]}x{size[1]}, {args.shading or scene.render.shading})")
    return 0


def run_pipeline(args: argparse.Namespace, pipeline, size: tuple[int, int]) -> int:
    """``render --pipeline NAME`` for a CPU pipeline: its defaults, the generic path."""
    for flag in RASTER_FLAGS:
        if getattr(args, flag, None) is not None:
            option = "--" + flag.replace("_", "-")
            raise ShadeLabError(f"{option}: applies to the raster pipelines, not "
                                f"{pipeline.name}")
    scene = load_preset(args.preset, list(args.set))
    pipeline.check(scene, args.preset)
    limits.check_pixels(size, bytes_per_pixel=64)
    check_outputs(args, scene)
    from shadelab.progress import run_to_end

    last = run_to_end(pipeline.run(scene, size), desc=pipeline.name)
    save_outputs(args, pipeline.image(last, size), scene.render.exposure)
    print(f"wrote {args.output} ({size[0]}x{size[1]}, {pipeline.name})")
    return 0


def run_presets(args: argparse.Namespace) -> int:
    for name in list_presets():
        raw = read_toml(resolve_preset(name))
        print(f"{name:24s} {raw.get('description', '')}")
    return 0


def run_validate(args: argparse.Namespace) -> int:
    for name in args.presets:
        scene = load_preset(name)
        from shadelab.geometry.mesh import scene_meshes

        meshes = scene_meshes(scene)  # mesh files must load too
        from shadelab.raster.textures import BUMP_MODES, TEXTURE_MODES, check_image_file

        for mname, m in scene.materials.items():  # and images be images within the limit
            if m.texture not in TEXTURE_MODES:
                check_image_file(m.texture, scene.base_dir, f"materials.{mname}.texture")
            if m.bump not in BUMP_MODES:
                check_image_file(m.bump, scene.base_dir, f"materials.{mname}.bump")
        triangles = sum(len(m.faces) for m in meshes)
        print(f"ok {name}: {len(scene.objects)} objects, {triangles} triangles, "
              f"{len(scene.lights)} lights")
    if not args.presets:
        raise ShadeLabError("validate: expected at least one preset")
    return 0
