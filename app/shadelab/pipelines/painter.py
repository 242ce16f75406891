"""``painter``: the GL renderer with list-priority visibility (the painter's algorithm)."""

from __future__ import annotations

from shadelab.pipelines.raster import RasterPipeline
from shadelab.pipelines.registry import register
from shadelab.scene.model import Scene


class PainterPipeline(RasterPipeline):
    visibility = "painter"

    def __init__(self) -> None:
        super().__init__("painter", "list priority + Phong", None, viewport=3)
        self.raster = ("phong", "painter")

    def prepared_for_run(self, scene: Scene) -> Scene:
        return self.prepared(scene)


register(PainterPipeline())
