"""Headless images for the exercises: raster renders through the public API (EGL). Kept
out of the package's other modules so that the viewer's Exercise window, which gets its
images from the GL side, never reaches ``shadelab.api`` (that would be an import cycle:
the API opens the viewer)."""

from __future__ import annotations

import numpy as np

from shadelab.exercises.tasks import Shot


def api_render(shot: Shot) -> np.ndarray:
    """The raster image of a shot through ``shadelab.render`` (headless EGL)."""
    from shadelab.api import render

    return render(shot.scene(), shot.size, shot.shading, specular=shot.specular).array
