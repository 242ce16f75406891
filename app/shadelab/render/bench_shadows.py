"""Shadow benchmark: cornell at 800x600, Phong, stencil shadow volumes for its point light,
and the same frame without shadows in the same run (goal: shadowed <= 2.5x unshadowed), and
the shadows / shadows-colored presets with m lights against issue 13.5's (1 + 0.6 m)x.

Frames end with ``ctx.finish()`` so the GPU (or llvmpipe) work is inside the timing. Also
reports the shadow-volume geometry sizes and the other shadow presets for context.
"""

from __future__ import annotations

from shadelab.gl.context import headless_context
from shadelab.gl.target import RenderTarget
from shadelab.render.renderer import Renderer
from shadelab.scene.preset import load_preset
from shadelab.timing import median_time

SIZE = (800, 600)


def _frame_timer(renderer: Renderer, target: RenderTarget, scene, repeats: int) -> dict:
    ctx = renderer.ctx

    def frame():
        renderer.render(scene, target, "phong")
        ctx.finish()

    return median_time(frame, repeats)


def run(quick: bool) -> dict:
    ctx = headless_context()
    renderer = Renderer(ctx)
    target = RenderTarget(ctx, SIZE)
    repeats = 5 if quick else 30
    try:
        plain = load_preset("cornell", ["render.shadows=none"])
        shadowed = load_preset("cornell", ["render.shadows=volumes"])
        zpass = load_preset("cornell", ["render.shadows=volumes", "render.shadow_method=zpass"])
        result = {"size": f"{SIZE[0]}x{SIZE[1]}", "shading": "phong"}
        result["cornell_no_shadows"] = _frame_timer(renderer, target, plain, repeats)
        result["cornell_shadow_volumes_zfail"] = _frame_timer(renderer, target, shadowed, repeats)
        result["cornell_shadow_volumes_zpass"] = _frame_timer(renderer, target, zpass, repeats)
        ratio = (result["cornell_shadow_volumes_zfail"]["median_ms"]
                 / result["cornell_no_shadows"]["median_ms"])
        result["ratio_shadowed_over_unshadowed"] = round(ratio, 3)
        result["goal_ratio"] = 2.5
        result["meets_goal"] = ratio <= 2.5
        volumes = renderer.shadow_volumes.volumes(shadowed, renderer.sync(shadowed), 0,
                                                  shadowed.active_lights()[0])
        result["cornell_volume_triangles"] = int(sum(len(v.volume.faces) for v in volumes))
        result["cornell_casters"] = {method: sum(v.volume.method == method for v in volumes)
                                     for method in ("silhouette", "open", "per-triangle")}
        if not quick:
            for name in ("shadows", "shadows-colored"):
                scene = load_preset(name)
                result[f"{name}_volumes"] = _frame_timer(renderer, target, scene, 10)
                scene.render.shadows = "none"
                result[f"{name}_no_shadows"] = _frame_timer(renderer, target, scene, 10)
                m = len(scene.active_lights())
                result[f"{name}_ratio"] = round(result[f"{name}_volumes"]["median_ms"]
                                                / result[f"{name}_no_shadows"]["median_ms"], 3)
                result[f"{name}_goal_ratio"] = 1.0 + 0.6 * m      # issue 13.5, m lights
                result[f"{name}_lights"] = m
        return result
    finally:
        target.release()
        renderer.release()
