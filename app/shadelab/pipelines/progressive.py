"""The generic coarse-to-fine wrapper: any image pipeline at 1/8, 1/4, 1/2, then full size.

Each level is a complete picture; the viewer shows it while the next one renders. Each step
streams at once, and the last one comes again marked done (``stats["done"]``), so the newest
Progress the viewer polls always carries the final image. A pipeline tunes its levels with
``level_state`` (shared by every level), ``level_options`` (per level, e.g. one sample until
full size), ``unit`` and ``work_done`` (what the status line counts).
"""

from __future__ import annotations

from typing import Iterator

from shadelab.progress import Progress
from shadelab.scene.model import Scene

LEVELS = (8, 4, 2, 1)        # resolution divisors, coarse to fine


def level_size(size: tuple[int, int], divisor: int) -> tuple[int, int]:
    return max(1, size[0] // divisor), max(1, size[1] // divisor)


def held_back(steps: Iterator[Progress]) -> Iterator[Progress]:
    """Yield every step as soon as it exists (the first full-resolution pass streams the
    moment its last tile is traced, not one chunk later), then the last one again, marked
    done: the viewer polls only the newest Progress, so the final one must carry the final
    image (not a bare 'done'). The done copy shares the last step's image."""
    last = None
    for step in steps:
        yield step
        last = step
    if last is not None:
        yield Progress(last.image, 1.0, "done: " + last.message,
                       dict(last.stats or {}, done=True))


def progressive(pipeline, scene: Scene, size: tuple[int, int],
                levels: tuple[int, ...] = LEVELS, **options) -> Iterator[Progress]:
    """``pipeline.run`` at each of ``levels`` (divisors of ``size``), coarse to fine."""
    return held_back(_levels(pipeline, scene, size, levels, options))


def _levels(pipeline, scene, size, levels, options) -> Iterator[Progress]:
    shared = dict(options, **pipeline.level_state(scene))
    unit = getattr(pipeline, "unit", "pixels")
    total = 0
    for li, div in enumerate(levels):
        sub = level_size(size, div)
        opts = dict(shared, **pipeline.level_options(scene, div))
        done = 0
        for step in pipeline.run(scene, sub, **opts):
            done = pipeline.work_done(step, sub, opts)
            yield Progress(step.image, (li + step.fraction) / len(levels),
                           f"1/{div} resolution ({sub[0]}x{sub[1]}), {step.message}, "
                           f"{total + done} {unit}",
                           {"level": div, "size": sub, unit: total + done, "unit": unit,
                            "level_work": done})
        total += done
