"""Radiosity: patches, form factors (hemicube, ray-cast, analytic), solvers, Gouraud display.

Pure layer: no GL anywhere. The GPU hemicube (:mod:`shadelab.raster.hemicube`) is passed in as
a backend (``hemicube=Hemicube``); the GL image is :mod:`shadelab.raster.radiosity_image`, and
:mod:`shadelab.raster.radiosity` binds the two to the solver. The main entry
points are re-exported lazily (numba and embreex load on first use):
``iter_radiosity``, ``solve_scene``, ``RadiositySolution`` (``shadelab.radiosity.solution``).
"""

from __future__ import annotations

_LAZY = {"iter_radiosity": "shadelab.radiosity.solution",
         "solve_scene": "shadelab.radiosity.solution",
         "RadiositySolution": "shadelab.radiosity.solution"}


def __getattr__(name: str):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'shadelab.radiosity' has no attribute {name!r}")
