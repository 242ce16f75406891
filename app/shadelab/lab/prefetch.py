"""Lesson prefetch: the next step's offline pipeline rendered ahead of time (pure logic).

While a lesson is open and the current step's own job is done (or it has none), the next
step's offline pipeline (Whitted ``raytrace``, ``pathtrace``, ``radiosity``) runs in a
runner of its own on that step's scene (preset + overrides) at the viewport's size. Its key
is :func:`step_key` (lesson, step, pipeline, size, path-tracing spp); when PageDown reaches
the step unedited, :mod:`shadelab.ui.pipelines` asks :meth:`Prefetch.take` with the same key
and the viewport adopts the runner, finished or still refining. A prefetch whose key no longer
matches the step after the current one (the teacher went elsewhere) is cancelled and dropped.
No GL, no GUI: the runner is anything with ``running``, ``cancel()`` (a JobRunner).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable


def step_key(run, index: int, name: str, size: tuple[int, int], spp: int) -> tuple:
    """What a lesson step's offline image depends on, known before the step is loaded: the
    lesson, the step, the pipeline, the size (radiosity: none, it is view-independent) and the
    path tracer's samples per pixel (the viewer's setting, not the scene's)."""
    return ("lesson", id(run.lesson), index, name,
            None if name == "radiosity" else tuple(size),
            int(spp) if name == "pathtrace" else None)


def next_offline(run, offline_names) -> tuple[int, str] | None:
    """(index, pipeline) of the step after the current one when it has an offline pipeline."""
    if run is None or run.step is None:
        return None
    index = run.index + 1
    if index >= len(run.lesson.steps):
        return None
    name = run.lesson.steps[index].pipeline
    return (index, name) if name in offline_names else None


def unedited(run, state) -> bool:
    """The scene is the current step's, as :func:`shadelab.lab.lesson.go_to` loaded it."""
    return run is not None and getattr(run, "loaded", None) == (state.scene_version,
                                                                state.scene.version)


@dataclass
class Prefetch:
    """The prefetched job: its runner, key, step and the scene it renders."""

    runner: object = None
    key: object = None
    index: int = -1
    scene: object = None
    size: tuple = (0, 0)
    record: object = None          # its JobRecord (``--bench-json``), when the caller keeps one
    enabled: bool = True

    def tick(self, wanted: tuple | None, current_busy: bool,
             start: Callable[[tuple], None]) -> bool:
        """Once a frame. ``wanted`` = (key, index, ...) of the next step's job, or None.
        Cancels a prefetch that no longer matches, or that runs while the current step is busy
        again; starts one (``start(wanted)``, which sets runner and scene) when the current step
        is settled. True when a prefetch was started."""
        if self.key is not None and (wanted is None or self.key != wanted[0]
                                     or (current_busy and self.running)):
            self.drop()
        if not self.enabled or wanted is None or current_busy or self.key is not None \
                or self.running:     # (a dropped job still stopping: start on a later frame)
            return False
        self.key, self.index = wanted[0], wanted[1]
        start(wanted)
        return True

    @property
    def running(self) -> bool:
        return self.runner is not None and bool(self.runner.running)

    def drop(self) -> None:
        """Forget the prefetched job (its runner stays, idle, for the next one)."""
        if self.running:
            self.runner.cancel()
        self.key, self.index, self.scene, self.record = None, -1, None, None

    def take(self, key, give_back=None):
        """The prefetched runner when ``key`` is its key (the step arrived unedited), else
        None (and a prefetch for another key is kept: :meth:`tick` decides on it). ``give_back``:
        the viewport's own runner, kept here for the next prefetch."""
        if self.key is None or key != self.key or self.runner is None:
            return None
        runner = self.runner
        self.runner = give_back
        self.key, self.index = None, -1
        return runner
