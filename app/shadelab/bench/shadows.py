"""Shadow benchmark: cornell at 800x600, Phong, stencil shadow volumes for its point light,
and the same frame without shadows in the same run (goal: shadowed <= 2.5x unshadowed), and
the shadows / shadows-colored presets with m lights against issue 13.5's (1 + 0.6 m)x.

Frames end with ``ctx.finish()`` so the GPU (or llvmpipe) work is inside the timing. The
ratios time the shadowed and the unshadowed frame alternately (A B A B ...,
:func:`shadelab.bench.raster.interleaved_ratio`) and take the median of the per-pair ratios,
so a shared machine's load falls on both alike. Also reports the shadow-volume geometry sizes
and the other shadow presets for context.
"""

from __future__ import annotations

from shadelab.bench.raster import interleaved_ratio
from shadelab.gl.context import headless_context
from shadelab.gl.target import RenderTarget
from shadelab.raster.renderer import Renderer
from shadelab.scene.preset import load_preset
from shadelab.timing import median_time

SIZE = (800, 600)


def _frame(renderer: Renderer, target: RenderTarget, scene):
    def frame():
        renderer.render(scene, target, "phong")
        renderer.ctx.finish()

    return frame


def _frame_timer(renderer: Renderer, target: RenderTarget, scene, repeats: int) -> dict:
    return median_time(_frame(renderer, target, scene), repeats)


def _shadowed_over_plain(renderer: Renderer, target: RenderTarget, shadowed, plain,
                         repeats: int) -> dict:
    """Both frames timed alternately; ``ratio``: the median of the per-pair ratios."""
    timed = interleaved_ratio(_frame(renderer, target, shadowed),
                              _frame(renderer, target, plain), repeats)
    return {"shadowed_median_ms": timed["ours_median_ms"],
            "unshadowed_median_ms": timed["bare_median_ms"],
            "ratio": round(timed["ratio_of_pairs_median"], 3),
            "ratio_of_medians": round(timed["ratio"], 3), "repeats": repeats}


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
        paired = _shadowed_over_plain(renderer, target, shadowed, plain, repeats)
        result["cornell_shadowed_vs_unshadowed_interleaved"] = paired
        ratio = paired["ratio"]
        result["ratio_shadowed_over_unshadowed"] = ratio
        result["goal_ratio"] = 1.6                        # issue 13.5: 1 + 0.6 m, one light
        result["meets_goal"] = ratio <= 1.6
        volumes = renderer.shadow_volumes.volumes(shadowed, renderer.sync(shadowed), 0,
                                                  shadowed.active_lights()[0])
        result["cornell_volume_triangles"] = int(sum(len(v.volume.faces) for v in volumes))
        result["cornell_casters"] = {method: sum(v.volume.method == method for v in volumes)
                                     for method in ("silhouette", "open", "per-triangle")}
        if not quick:
            for name in ("shadows", "shadows-colored"):
                scene = load_preset(name)
                bare = load_preset(name, ["render.shadows=none"])
                paired = _shadowed_over_plain(renderer, target, scene, bare, 10)
                result[f"{name}_volumes"] = {"median_ms": paired["shadowed_median_ms"]}
                result[f"{name}_no_shadows"] = {"median_ms": paired["unshadowed_median_ms"]}
                m = len(scene.active_lights())
                result[f"{name}_ratio"] = paired["ratio"]
                result[f"{name}_goal_ratio"] = 1.0 + 0.6 * m      # issue 13.5, m lights
                result[f"{name}_lights"] = m
        return result
    finally:
        target.release()
        renderer.release()
