"""Raster benchmark: frame time per preset and shading mode, time to first image, and a bare
moderngl per-fragment Phong draw of the same triangles for a noise-proof ratio."""

from __future__ import annotations

import dataclasses
import statistics
import time

import moderngl
import numpy as np

from shadelab.geometry.mesh import scene_meshes
from shadelab.gl.context import create_headless_context, headless_context, make_current
from shadelab.gl.programs import load_program, set_uniform
from shadelab.gl.target import RenderTarget, release_framebuffer
from shadelab.raster.renderer import Renderer, make_view, triangle_soup
from shadelab.scene.camera import gl_matrix
from shadelab.scene.preset import list_presets, load_preset
from shadelab.timing import median_time, scaling

SIZE = (800, 600)
# The scenes of the paired ratio (issue 13.1): name, preset, overrides. mesh80k: the
# sphere-shading icosphere subdivided 6 times, 20 * 4^6 = 81920 triangles.
PHONG_VS_BARE = (("cornell", "cornell", []), ("sphere_shading", "sphere-shading", []),
                 ("mesh80k", "sphere-shading", ["objects.0.subdivisions=6"]))
FAIRNESS = ("both sides: the same scene's triangles (scene_meshes) in the same order, "
            f"{SIZE[0]}x{SIZE[1]}, an RGBA32F color texture with a 24-bit depth buffer (ours: "
            "DEPTH24_STENCIL8, the stencil cleared too; bare: DEPTH_COMPONENT24), no MSAA, depth "
            "test on, one clear and one ctx.finish() per frame, timed A B A B ... after 3 warm-up "
            "pairs; ours: Renderer.render (Phong, the preset's lights and materials; the back "
            "faces of closed meshes seen from outside culled, as the renderer always does: the "
            "80k-triangle sphere's ratio is below 1 for that; materials with ks = 0, all of "
            "cornell's, drawn by the diffuse twin with no specular lobe, bit-identical); bare: "
            "one VAO of position + "
            "normal, one point light, a minimal per-fragment Phong program (ks a uniform: its "
            "lobe is evaluated on every fragment), every face drawn "
            "(cornell's room is seen from inside: nothing of it is culled)")


def time_to_first_image() -> float:
    """Seconds from a new EGL context to the first cornell image read back."""
    shared = headless_context()
    start = time.perf_counter()
    ctx = create_headless_context()
    renderer = Renderer(ctx)
    target = RenderTarget(ctx, SIZE)
    renderer.render(load_preset("cornell"), target)
    target.read()
    elapsed = time.perf_counter() - start
    renderer.release()
    target.release()
    ctx.release()
    make_current(shared)  # the new context was current; give the process's context back
    return elapsed


def bare_phong_frame(ctx: moderngl.Context, preset: str, overrides: list[str] | None = None):
    """The same triangles in one VAO, one light, a plain framebuffer: the floor we compare to.

    Returns ``(frame, release)``: draw one frame (finished), and free the GL objects.
    """
    scene = load_preset(preset, overrides or [])
    meshes = scene_meshes(scene)
    soup = np.concatenate([triangle_soup(m)[:, :6] for m in meshes]).astype("f4")
    program = load_program(ctx, "bare_phong")
    vbo = ctx.buffer(soup.tobytes())
    vao = ctx.vertex_array(program, [(vbo, "3f 3f", "in_position", "in_normal")])
    fbo = ctx.framebuffer(ctx.texture(SIZE, 4, dtype="f4"), ctx.depth_renderbuffer(SIZE))
    view = make_view(scene, SIZE, meshes)
    set_uniform(program, "u_clip_from_world", gl_matrix(view.clip_from_world))
    set_uniform(program, "u_eye", tuple(view.eye))
    set_uniform(program, "u_light_position", tuple(scene.lights[0].position))
    set_uniform(program, "u_light_Ip", tuple(scene.lights[0].Ip))
    set_uniform(program, "u_Od", (0.7, 0.7, 0.7))
    set_uniform(program, "u_ks", 0.0)  # a uniform: the compiler cannot drop the specular term
    set_uniform(program, "u_n", 10.0)

    def frame():
        fbo.use()
        fbo.clear(0.0, 0.0, 0.0, 1.0, depth=1.0)
        ctx.enable_only(moderngl.DEPTH_TEST)
        vao.render(moderngl.TRIANGLES)
        ctx.finish()

    def release():
        for res in (vao, vbo, program):
            res.release()
        release_framebuffer(ctx, fbo)

    return frame, release


def interleaved_ratio(ours, bare, repeats: int) -> dict:
    """Time two frame functions alternately (A B A B ...), so both see the same machine load;
    the ratio of their medians stays meaningful on a noisy machine."""
    for _ in range(3):
        ours()
        bare()
    a, b = [], []
    for _ in range(repeats):
        for fn, samples in ((ours, a), (bare, b)):
            start = time.perf_counter()
            fn()
            samples.append((time.perf_counter() - start) * 1000.0)
    return {"ours_median_ms": statistics.median(a), "bare_median_ms": statistics.median(b),
            "ratio": statistics.median(a) / statistics.median(b),
            "ratio_of_pairs_median": statistics.median(x / y for x, y in zip(a, b, strict=True)),
            "repeats": repeats}


def phong_vs_bare(renderer: Renderer, target: RenderTarget, preset: str, overrides: list[str],
                  repeats: int) -> dict:
    """Our Phong frame of ``preset`` against :func:`bare_phong_frame` of the same triangles,
    timed interleaved (:func:`interleaved_ratio`)."""
    ctx = renderer.ctx
    scene = load_preset(preset, overrides)
    bare, release_bare = bare_phong_frame(ctx, preset, overrides)

    def ours():
        renderer.render(scene, target, "phong")
        ctx.finish()

    try:
        paired = interleaved_ratio(ours, bare, repeats)
    finally:
        release_bare()
    return {"preset": preset, "overrides": overrides,
            "triangles": sum(len(m.faces) for m in scene_meshes(scene)), **paired}


def hemicube_form_factors(patches: int = 400, resolution: int = 128, repeats: int = 3) -> dict:
    """Seconds for the full hemicube form-factor matrix of cornell (GPU item buffers, one
    read-back per batch of patches, one bincount per batch); goal <= 1 s for 400 patches
    on llvmpipe (issue 13.4). Here, not in the radiosity section: that layer has no GL."""
    from shadelab.radiosity.formfactors import FormFactors
    from shadelab.radiosity.patches import uniform_patches
    from shadelab.raster.hemicube import Hemicube

    patch_set = uniform_patches(load_preset("cornell"), patches)
    timing = median_time(lambda: FormFactors(patch_set, "hemicube", resolution,
                                             hemicube=Hemicube).matrix(), repeats, warmup=1)
    return {"patches": len(patch_set), "resolution": resolution, **timing,
            "seconds": timing["median_ms"] / 1000.0, "goal_s": 1.0}


def raster_scaling(renderer: Renderer, target: RenderTarget, quick: bool) -> dict:
    """Phong frame time against triangle count: icospheres (20 * 4^k triangles) of
    sphere-shading, up to three of them for ~1M triangles (--quick: up to ~80k)."""
    ctx = renderer.ctx
    levels = [(3, 1), (4, 1), (5, 1), (6, 1)] if quick else [(3, 1), (4, 1), (5, 1), (6, 1),
                                                             (7, 1), (7, 3)]
    counts, seconds = [], []
    for level, copies in levels:
        scene = load_preset("sphere-shading", [f"objects.0.subdivisions={level}"])
        for k in range(1, copies):
            scene.objects.append(dataclasses.replace(scene.objects[0], name=f"sphere{k}"))

        def frame(scene=scene):
            renderer.render(scene, target, "phong")
            ctx.finish()

        timing = median_time(frame, 3 if quick else 5)
        counts.append(sum(len(m.faces) for m in scene_meshes(scene)))
        seconds.append(timing["median_ms"] / 1000.0)
    return scaling(counts, seconds, "triangles")


def run(quick: bool) -> dict:
    ctx = headless_context()
    renderer = Renderer(ctx)
    target = RenderTarget(ctx, SIZE)
    repeats = 5 if quick else 40
    frames = {}
    presets = ["cornell", "sphere-shading"] if quick else list_presets()
    for name in presets:
        scene = load_preset(name)
        for shading in ("flat", "gouraud", "phong"):
            def frame(scene=scene, shading=shading):
                renderer.render(scene, target, shading)
                ctx.finish()

            frames[f"{name}/{shading}"] = median_time(frame, repeats)
    pairs = {name: phong_vs_bare(renderer, target, preset, overrides, 2 * repeats)
             for name, preset, overrides in PHONG_VS_BARE}
    paired = pairs["cornell"]
    scaling_figure = raster_scaling(renderer, target, quick)
    renderer.release()
    target.release()
    return {
        "size": list(SIZE),
        "frame_ms": frames,
        "bare_moderngl_phong_cornell": {"median_ms": paired["bare_median_ms"]},
        "cornell_phong_vs_bare_interleaved": paired,
        "cornell_phong_over_bare": paired["ratio"],
        "sphere_shading_phong_over_bare": pairs["sphere_shading"]["ratio"],
        "mesh80k_phong_over_bare": pairs["mesh80k"]["ratio"],
        "phong_vs_bare_interleaved": pairs,
        "phong_vs_bare_fairness": FAIRNESS,
        "time_to_first_image_s": time_to_first_image(),
        "hemicube_form_factors": hemicube_form_factors(repeats=2 if quick else 3),
        "scaling_frame_vs_triangles": scaling_figure,
        "goal": "cornell_phong_over_bare <= 1.15 (and the same ratio for sphere_shading and "
                "mesh80k)",
    }
