"""``pathtrace``: Monte Carlo path tracing, the reference radiance
(:func:`shadelab.raytrace.pathtrace.iter_pathtrace`)."""

from __future__ import annotations

from typing import Iterator

from shadelab.pipelines.base import BasePipeline
from shadelab.pipelines.raytrace import check_objects
from shadelab.pipelines.registry import register
from shadelab.progress import Progress
from shadelab.scene.model import Scene

DEFAULT_SPP = 64   # shadelab.render's and shadelab pathtrace's samples per pixel
VIEWPORT_LEVELS = (8, 4, 1)   # the viewer's levels: no half size (a quarter of a full pass
                              # before the first full-resolution sample; the full level
                              # refines in place, sample by sample)


class PathtracePipeline(BasePipeline):
    name = "pathtrace"
    label = "path tracing (reference)"
    options = ("spp", "seed", "backend", "workers")
    default_size = (256, 256)
    viewport = 6
    job_label = "Path tracer (reference GI)"
    job_order = 3
    unit = "samples"
    samples_setting = True   # the Offline panel shows a samples-per-pixel slider for it

    def check(self, scene: Scene, label: str = "") -> None:
        from shadelab.raytrace.pathtrace import check_lit

        label = label or scene.name or "scene"
        check_objects(scene, label)
        check_lit(scene, label)

    def run(self, scene: Scene, size: tuple[int, int], spp: int | None = None, seed: int = 0,
            backend: str = "auto", workers: int = 1) -> Iterator[Progress]:
        from shadelab.raytrace.pathtrace import iter_pathtrace

        spp = DEFAULT_SPP if spp is None else spp
        return iter_pathtrace(scene, size, spp, seed, backend, workers=workers)

    def info(self, last: Progress, options: dict) -> dict:
        spp = options.get("spp")
        return dict(last.stats, spp=DEFAULT_SPP if spp is None else spp)

    def job(self, scene: Scene, size: tuple[int, int]) -> Iterator[Progress]:
        """At the scene's samples per pixel (the Offline panel sets them)."""
        return self.run(scene, size, max(scene.raytrace.spp, 1), seed=1)

    def viewport_job(self, scene: Scene, size: tuple[int, int]) -> Iterator[Progress]:
        """Coarse to fine at :data:`VIEWPORT_LEVELS`: 1/8 and 1/4 size at one sample, then
        full size at the scene's samples per pixel."""
        from shadelab.pipelines.progressive import progressive

        return progressive(self, scene, size, VIEWPORT_LEVELS)

    def level_options(self, scene: Scene, divisor: int) -> dict:
        return {"spp": max(int(scene.raytrace.spp), 1) if divisor == 1 else 1, "seed": 1}

    def work_done(self, step: Progress, size, options) -> int:
        return int(round(step.fraction * options["spp"] * size[0] * size[1]))


register(PathtracePipeline())
