"""The viewer's GL side of :class:`shadelab.lab.gpu_queue.GpuQueue` (GL thread only).

Once per frame, before the panels draw, :meth:`GpuSide.flush` uploads the images the panels
queued (textures registered by id and size) and runs their requests on the viewer's
:class:`shadelab.ui.viewport.Viewport`; the GL objects (textures, panes, hemicubes) stay here.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from shadelab.lab.gpu_queue import GpuQueue, Texture
from shadelab.ui.viewport import Viewport


class GpuSide:
    """Serves one queue with one viewport: uploads, then requests, in the order queued."""

    def __init__(self, viewport: Viewport):
        self.viewport = viewport
        self._hemicube = None          # (geometry key, Hemicube) of the last hemicube request
        self.handlers: dict[str, Callable[[str, dict], object]] = {
            "raster": self._raster,
            "hemicube_rows": self._hemicube_rows,
            "hemicube_images": self._hemicube_images,
        }

    def flush(self, queue: GpuQueue) -> None:
        queue.attached = True
        self.flush_uploads(queue)
        while queue.requests:
            key = next(iter(queue.requests))
            request = queue.requests.pop(key)
            handler = self.handlers.get(request.kind)
            try:
                if handler is None:
                    raise ValueError(f"no GPU handler for '{request.kind}'")
                queue.results[key] = handler(key, request.args)
            except Exception as exc:  # shown by the panel that asked; the session goes on
                queue.errors[key] = f"{request.kind}: {exc}"
            finally:
                self.viewport.restore()

    def flush_uploads(self, queue: GpuQueue) -> None:
        while queue.uploads:
            key = next(iter(queue.uploads))
            tex = self.viewport.upload_image(key, queue.uploads.pop(key))
            queue.textures[key] = Texture(int(tex.glo), tuple(tex.size))

    # ------------------------------------------------------------ handlers
    def _raster(self, key: str, args: dict) -> np.ndarray:
        """The scene's raster image, linear (H, W, 3) float32, row 0 at the top."""
        pane = f"request:{key}"
        self.viewport.draw_scene(pane, args["scene"], args["size"], args["shading"],
                                 args["specular"])
        return self.viewport.read_linear(pane)

    def _cube(self, args: dict):
        from shadelab.raster.hemicube import Hemicube

        key = args["key"]
        if self._hemicube is None or self._hemicube[0] != key:
            self.release_hemicube()
            self._hemicube = (key, Hemicube(args["patches"], args["resolution"],
                                            ctx=self.viewport.ctx))
        return self._hemicube[1]

    def _hemicube_rows(self, key: str, args: dict) -> dict:
        """Rows ``start`` .. ``start + batch`` of F (one atlas read-back)."""
        cube = self._cube(args)
        n = len(args["patches"])
        rows = np.arange(args["start"], min(n, args["start"] + cube.batch))
        return {"key": args["key"], "rows": rows, "values": cube.rows(rows),
                "batch": cube.batch, "res": cube.res}

    def _hemicube_images(self, key: str, args: dict) -> dict:
        """:meth:`Hemicube.item_images` of patch ``patch``."""
        cube = self._cube(args)
        return {"key": args["key"], "patch": args["patch"], "res": cube.res,
                "images": cube.item_images(args["patch"])}

    def release_hemicube(self) -> None:
        if self._hemicube is not None:
            self._hemicube[1].release()
            self._hemicube = None

    def release(self) -> None:
        self.release_hemicube()
