"""The Studies and Failure-gallery panels' logic, without GUI: run a study off the UI thread,
turn its result into plot series and an auto-quality choice, open a gallery case.

Pure module (threads, processes and numpy only; no GL, no imgui): :mod:`shadelab.ui.studies_panel`
draws it. A study renders with its own headless GL context, so it runs in a worker *process*
(:class:`shadelab.lab.jobs.JobRunner`), never next to the viewer's window context.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Iterator

from shadelab.errors import ShadeLabError
from shadelab.lab.jobs import JobRunner
from shadelab.progress import Progress

# ---------------------------------------------------------------- running a study


def study_job(name: str, quick: bool) -> Iterator[Progress]:
    """One study as a job (module level: it pickles into the worker process).

    Yields a single Progress whose ``stats["result"]`` is the :class:`StudyResult`.
    """
    from shadelab.studies import run_study

    yield Progress(None, 0.0, f"running the {name} study")
    result = run_study(name, quick=quick)
    yield Progress(None, 1.0, f"{name}: {len(result.rows)} rows", {"result": result})


@dataclass
class StudyRun:
    """The Studies panel's job: which study ran, its result, or why there is none."""

    runner: JobRunner = field(default_factory=JobRunner)
    name: str = ""
    quick: bool = True
    result: object = None          # shadelab.studies.result.StudyResult of the last finished run
    error: str = ""                # any other failure of the last run
    _seen: int = -1

    def start(self, name: str, quick: bool = True) -> None:
        self.name, self.quick = name, quick
        self.error = ""
        self._seen = -1
        self.runner.start(f"study {name}", lambda: study_job(name, quick),
                          call=(study_job, name, quick))

    @property
    def running(self) -> bool:
        return self.runner.running

    @property
    def elapsed(self) -> float:
        return self.runner.elapsed

    def poll(self) -> None:
        """Take a finished job's result (or its error); call once a frame."""
        if not self.runner.started or self.runner.running or self._seen == self.runner.version:
            return
        latest, version = self.runner.snapshot()
        self._seen = version
        error = self.runner.error
        if error:
            self.error = error
        elif self.runner.cancelled:
            self.error = "cancelled"
        elif latest is not None and "result" in latest.stats \
                and not isinstance(latest.stats["result"], str):
            self.result = latest.stats["result"]
        else:
            self.error = "the study ended without a result"

    def cancel(self) -> None:
        self.runner.cancel()

    def shutdown(self) -> None:
        self.runner.shutdown()


# ---------------------------------------------------------------- plotting data


def _number(value) -> float | None:
    try:
        x = float(value)
    except (TypeError, ValueError):
        return None
    return x if math.isfinite(x) else None


def plot_series(result) -> list[tuple[str, list[float], list[float], list[str]]]:
    """(series name, xs, ys, point labels) per series, as charts.py draws them.

    Non-numeric points are left out; on a log axis non-positive values are left out on x and
    put one decade below the smallest positive value on y (an exact zero error stays visible).
    """
    ys_all = [_number(v) for v in result.column(result.y)] if result.y else []
    positive = [v for v in ys_all if v is not None and v > 0.0]
    floor = min(positive) / 10.0 if positive else 1e-12
    out = []
    for name, rows in result.series().items():
        labels = [str(v) for v in result.column(result.label, rows)] if result.label \
            else [""] * len(rows)
        xs, ys, names = [], [], []
        for x, y, text in zip(result.column(result.x, rows), result.column(result.y, rows),
                              labels, strict=True):
            x, y = _number(x), _number(y)
            if x is None or y is None or (result.log_x and x <= 0.0):
                continue
            xs.append(x)
            ys.append(max(y, floor) if result.log_y else y)
            names.append(text)
        out.append((name, xs, ys, names))
    return out


def study_front(result) -> list:
    """The result's (cost = x, error = y) points as FrontPoints, when it has a front.

    Each point's setting names its series (the ``group`` column) and its label column, e.g.
    ``{"method": "phong", "level": 3}``; an empty list when the study draws no front.
    """
    from shadelab.studies.autoquality import FrontPoint

    if not (getattr(result, "front", False) and result.x and result.y):
        return []
    keys = [k for k in (result.group, result.label) if k]
    points = []
    for record in result.records():
        cost, error = _number(record.get(result.x)), _number(record.get(result.y))
        if cost is None or error is None:
            continue
        points.append(FrontPoint({k: record[k] for k in keys}, cost, error))
    return points


def auto_quality_line(result, budget: float) -> str:
    """What ``choose_setting`` picks on the result's front for ``budget``, as one line."""
    from shadelab.studies.autoquality import choose_setting, pareto_front

    points = study_front(result)
    if not points:
        return "auto quality: this study has no speed/accuracy front"
    try:
        choice = choose_setting(points, budget)
    except ShadeLabError as exc:
        return f"auto quality: {exc}"
    setting = ", ".join(f"{k} {v}" for k, v in choice.point.setting.items()) or "(point)"
    verdict = "meets" if choice.met else "misses (most accurate on the front)"
    return (f"auto quality: {setting}  ({result.x} {choice.point.cost:.4g}, {result.y} "
            f"{choice.point.error:.3g} {verdict} budget {budget:.3g}; "
            f"{len(pareto_front(points))} points on the front)")


def cell(value) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


# ---------------------------------------------------------------- the failure gallery


def case_shading(case) -> str | None:
    """The raster shading mode a ``raster:<shading>`` case is drawn with, else None."""
    kind, _, variant = case.method.partition(":")
    return (variant or None) if kind == "raster" else None


def offline_job_of(case) -> str:
    """The registry name of the offline pipeline a case is shown with ('' for raster)."""
    from shadelab import pipelines

    name = case.method.partition(":")[0]
    if name not in pipelines.all_names() or pipelines.get(name).raster is not None:
        return ""
    return name


def offline_job_label(case) -> str:
    """The label of :func:`offline_job_of`'s pipeline ('' for raster)."""
    from shadelab import pipelines

    name = offline_job_of(case)
    return pipelines.get(name).label if name else ""


def load_case_scene(case):
    """The case's scene: its preset with its ``--set`` overrides and its raster shading mode.

    Raises ShadeLabError (bad preset, override or mesh) with the loader's one-line message.
    """
    from shadelab.geometry.mesh import scene_meshes
    from shadelab.scene.preset import load_preset

    scene = load_preset(case.preset, list(case.overrides))
    shading = case_shading(case)
    if shading is not None:
        scene.render.shading = shading
    scene_meshes(scene)  # mesh files must load too, before the scene is swapped
    return scene


def open_case(state, case) -> bool:
    """Load a gallery case into the viewer as "open preset" does; an error keeps the scene."""
    try:
        scene = load_case_scene(case)
    except ShadeLabError as exc:
        state.error = f"gallery case '{case.name}': {exc}"
        return False
    state.replace_scene(scene, case.preset, new_file=True)
    state.studies.gallery_opened = case.name
    note = ""
    job = offline_job_label(case)
    if job:
        note = f"; run the {job} offline renderer ({case.method}) to see the failure"
    state.error, state.status = "", f"opened gallery case {case.name} ({case.preset}){note}"
    return True
