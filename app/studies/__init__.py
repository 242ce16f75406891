"""Speed-against-accuracy studies, error metrics, auto quality and the failure gallery.

Each study module has ``run_<study>(quick: bool) -> StudyResult`` (pure data: rows and
columns the viewer's Studies panel plots with ImPlot and ``shadelab charts`` draws with
matplotlib). Modules of other layers (ray tracer, radiosity, shadow volumes) are imported
lazily; a study whose renderer is not built yet raises :class:`StudySkipped`.
"""

from app.studies.result import StudyResult, StudySkipped

__all__ = ["StudyResult", "StudySkipped"]
