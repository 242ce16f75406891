"""Speed-against-accuracy studies, error metrics, auto quality and the failure gallery.

Each study module has ``run_<study>(quick: bool) -> StudyResult`` (pure data: rows and
columns the viewer's Studies panel plots with ImPlot and ``shadelab charts`` draws with
matplotlib). Modules of other layers (ray tracer, radiosity, shadow volumes) are imported
lazily, when their study runs.

For the viewer::

    from shadelab.studies import STUDIES, run_study
    for name, title in STUDIES: ...
    result = run_study("shading", quick=True)      # StudyResult
    for series, rows in result.series().items():
        xs, ys = result.column(result.x, rows), result.column(result.y, rows)
"""

from __future__ import annotations

import importlib

from shadelab.studies.result import StudyResult

# name -> (module, function, title)
_STUDY_TABLE = {
    "shading": ("shadelab.studies.shading_study", "run_shading",
                "Flat / Gouraud / Phong vs tessellation"),
    "raytrace": ("shadelab.studies.raytrace_study", "run_raytrace", "Ray tracing: depth and spp"),
    "radiosity": ("shadelab.studies.radiosity_study", "run_radiosity",
                  "Radiosity: patches, form factors, solvers"),
    "shadows": ("shadelab.studies.shadow_study", "run_shadows", "Shadow volumes vs shadow rays"),
}
STUDIES: tuple[tuple[str, str], ...] = tuple((n, t[2]) for n, t in _STUDY_TABLE.items())


def run_study(name: str, quick: bool = True) -> StudyResult:
    """Run one study by name (one of :data:`STUDIES`)."""
    module_name, function, _ = _STUDY_TABLE[name]
    return getattr(importlib.import_module(module_name), function)(quick)


__all__ = ["STUDIES", "StudyResult", "run_study"]
