"""What the panels ask of the GPU, as plain data (no GL, no GUI).

Panels never hold a GL object. They put numpy images to show (:meth:`GpuQueue.upload`) and
GPU work (:meth:`GpuQueue.request`: "render the raster view of this scene at this size",
"these rows of the hemicube form factors") into ``state.gpu``; the viewer's GL side
(:mod:`shadelab.ui.gpu_side`) uploads and runs them once per frame before the panels draw,
and leaves plain results: numpy arrays (:meth:`GpuQueue.take`) and textures as an int id and a
size (:meth:`GpuQueue.texture`, for ``imgui.image(imgui.ImTextureRef(t.id), ...)``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Texture:
    """An uploaded image as imgui needs it: the GL texture name and (width, height)."""

    id: int
    size: tuple[int, int]


@dataclass
class Request:
    """GPU work for the GL side: ``kind`` names its handler, ``args`` are plain data."""

    kind: str
    args: dict


@dataclass
class GpuQueue:
    """Uploads and requests waiting for the GL side, and what it left for the panels."""

    attached: bool = False            # a GL side serves this queue (the viewer's window is up)
    uploads: dict[str, np.ndarray] = field(default_factory=dict)   # key -> (H, W, 3) uint8
    requests: dict[str, Request] = field(default_factory=dict)     # key -> work to run
    textures: dict[str, Texture] = field(default_factory=dict)     # key -> uploaded texture
    results: dict[str, object] = field(default_factory=dict)       # key -> a request's result
    errors: dict[str, str] = field(default_factory=dict)           # key -> a request's error

    def upload(self, key: str, image: np.ndarray) -> None:
        """Show ``image`` ((H, W, 3) uint8, or (H, W, 4) with its alpha, row 0 at the top) as
        texture ``key`` (replaces what waits under that key)."""
        image = np.asarray(image)
        if image.ndim != 3 or image.shape[2] not in (3, 4) or image.dtype != np.uint8:
            raise ValueError(f"upload '{key}': expected (H, W, 3) or (H, W, 4) uint8, got "
                             f"{image.shape} {image.dtype}")
        self.uploads[key] = np.ascontiguousarray(image)

    def texture(self, key: str) -> Texture | None:
        return self.textures.get(key)

    def request(self, key: str, kind: str, /, **args) -> None:
        """Ask for GPU work; its result appears under ``key`` (an older one is dropped)."""
        self.requests[key] = Request(kind, args)
        self.results.pop(key, None)
        self.errors.pop(key, None)

    def pending(self, key: str) -> bool:
        return key in self.requests

    def take(self, key: str):
        """The result of request ``key`` once (None while it waits, or after an error:
        see :attr:`errors`)."""
        return self.results.pop(key, None)
