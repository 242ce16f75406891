"""Wall-clock timing for the benchmark sections (``shadelab bench``); pure, no GL."""

from __future__ import annotations

import statistics
import time
from typing import Callable


def median_time(fn: Callable[[], object], repeats: int, warmup: int = 2) -> dict:
    """Median, min and max wall time of ``fn`` in milliseconds."""
    for _ in range(warmup):
        fn()
    samples = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        samples.append((time.perf_counter() - start) * 1000.0)
    return {"median_ms": statistics.median(samples), "min_ms": min(samples),
            "max_ms": max(samples), "repeats": repeats}


def fitted_exponent(xs, ys) -> float | None:
    """Slope of the least-squares line through (log x, log y): cost ~ x^slope. None with
    fewer than two usable points."""
    import math

    points = [(math.log(x), math.log(y)) for x, y in zip(xs, ys, strict=True) if x > 0 and y > 0]
    if len(points) < 2:
        return None
    mx = sum(p[0] for p in points) / len(points)
    my = sum(p[1] for p in points) / len(points)
    sxx = sum((p[0] - mx) ** 2 for p in points)
    if sxx == 0.0:
        return None
    return sum((p[0] - mx) * (p[1] - my) for p in points) / sxx


def scaling(xs, seconds, x_name: str) -> dict:
    """A scaling figure: the points and the fitted exponent of seconds against ``x_name``."""
    return {"points": [{x_name: x, "seconds": s} for x, s in zip(xs, seconds, strict=True)],
            "exponent": fitted_exponent(xs, seconds)}
