"""The GL z-buffer pipelines: ``gouraud``, ``phong`` and ``flat`` (and ``raster``, the alias
that shades as the scene says). The renderer is imported inside ``run`` (GL stays lazy)."""

from __future__ import annotations

import copy
from typing import Iterator

from shadelab.errors import ShadeLabError
from shadelab.pipelines.base import BasePipeline
from shadelab.pipelines.registry import register
from shadelab.progress import Progress
from shadelab.scene.model import SHADING_MODES, SPECULAR_MODELS, Scene


class RasterPipeline(BasePipeline):
    """moderngl passes (``shadelab.raster.Renderer``): one finished image, no levels."""

    options = ("shading", "specular")
    default_size = (800, 600)
    visibility = "zbuffer"
    shading: str | None = None   # None: the scene's render.shading (or the shading option)

    def __init__(self, name: str, label: str, shading: str | None, viewport: int = 0):
        self.name, self.label, self.shading, self.viewport = name, label, shading, viewport
        self.raster = (shading or "phong", self.visibility)

    def check_options(self, shading=None, specular=None, **_) -> None:
        if shading is not None and shading not in SHADING_MODES:
            raise ShadeLabError(f"shading '{shading}': expected one of "
                                f"{', '.join(SHADING_MODES)}")
        if shading is not None and self.shading is not None and shading != self.shading:
            raise ShadeLabError(f"shading '{shading}': the {self.name} pipeline shades "
                                f"{self.shading}")
        if specular is not None and specular not in SPECULAR_MODELS:
            raise ShadeLabError(f"specular '{specular}': expected one of "
                                f"{', '.join(SPECULAR_MODELS)}")

    def prepared(self, scene: Scene) -> Scene:
        """The scene with this pipeline's visibility (a copy when it differs)."""
        if scene.render.visibility != self.visibility:
            scene = copy.deepcopy(scene)
            scene.render.visibility = self.visibility
        return scene

    def shading_of(self, scene: Scene, shading: str | None = None) -> str:
        return self.shading or shading or scene.render.shading

    def run(self, scene: Scene, size: tuple[int, int], shading: str | None = None,
            specular: str | None = None) -> Iterator[Progress]:
        self.check_options(shading, specular)
        from shadelab.raster.offscreen import render_image  # GL only once asked for

        shading = self.shading or shading
        image = render_image(self.prepared_for_run(scene), size, shading, specular)
        yield Progress(image, 1.0, "done", {"shading": self.shading_of(scene, shading)})

    def prepared_for_run(self, scene: Scene) -> Scene:
        # ``raster`` keeps the scene's visibility, as the CLI's ``render`` does; the named
        # z-buffer pipelines force the z-buffer (as the viewer's selector does)
        return scene if self.shading is None else self.prepared(scene)

    def viewport_job(self, scene: Scene, size: tuple[int, int]) -> Iterator[Progress]:
        return self.run(scene, size)


register(RasterPipeline("gouraud", "z-buffer + Gouraud", "gouraud", viewport=1))
register(RasterPipeline("phong", "z-buffer + Phong", "phong", viewport=2))
register(RasterPipeline("flat", "z-buffer + flat", "flat"))
register(RasterPipeline("raster", "z-buffer (the scene's shading)", None))
