"""Auto quality: the cheapest setting on a measured speed/accuracy front that meets an error budget.

A front is a list of :class:`FrontPoint` (setting, cost, error). :func:`pareto_front` keeps
the points no other point beats on both cost and error; :func:`choose_setting` walks it from
the cheapest end. The budget is in relative MSE (:func:`shadelab.studies.metrics.relmse`) unless a
study says otherwise, so ``--error 0.01`` reads "relative MSE at most 1 %".
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from shadelab.errors import ShadeLabError


@dataclass(frozen=True)
class FrontPoint:
    """One measured setting: what to set, what it cost and how wrong it was."""

    setting: dict = field(hash=False)   # e.g. {"subdivisions": 3} or {"depth": 4, "spp": 16}
    cost: float                         # e.g. milliseconds, triangles, rays
    error: float                        # e.g. relative MSE against the reference


@dataclass(frozen=True)
class Choice:
    """The outcome of :func:`choose_setting`; ``met`` is False when nothing reaches the budget."""

    point: FrontPoint
    met: bool
    budget: float


def front_from_rows(rows: list[dict], keys: tuple[str, ...], cost: str,
                    error: str = "relmse") -> list[FrontPoint]:
    """Front points from study records: ``keys`` name the setting columns."""
    return [FrontPoint({k: row[k] for k in keys}, float(row[cost]), float(row[error]))
            for row in rows]


def pareto_front(points: list[FrontPoint]) -> list[FrontPoint]:
    """The non-dominated points, cheapest first; along it the error strictly decreases."""
    ordered = sorted(points, key=lambda p: (p.cost, p.error))
    front: list[FrontPoint] = []
    for point in ordered:
        if not math.isfinite(point.error) or not math.isfinite(point.cost):
            continue
        if not front or point.error < front[-1].error:
            front.append(point)
    return front


def check_budget(budget: float, flag: str = "--error") -> float:
    """A usable error budget: a finite number > 0, else a one-line error."""
    if isinstance(budget, bool) or not isinstance(budget, (int, float)) \
            or not math.isfinite(budget) or budget <= 0.0:
        raise ShadeLabError(f"{flag} {budget!r}: expected a finite error budget > 0 "
                            f"(relative MSE, e.g. 0.01)")
    return float(budget)


def choose_setting(front: list[FrontPoint], budget: float) -> Choice:
    """The cheapest point of the front whose error is within ``budget``.

    When no point meets the budget the most accurate point is returned with ``met=False``
    (the caller reports it); an empty front or a bad budget is an error.
    """
    budget = check_budget(budget)
    points = pareto_front(front)
    if not points:
        raise ShadeLabError("auto quality: no measured setting to choose from")
    for point in points:
        if point.error <= budget:
            return Choice(point, True, budget)
    return Choice(points[-1], False, budget)


def parse_budget(text: str, flag: str = "--error") -> float:
    """argparse ``type=`` for ``--error``: a float > 0 or a one-line error."""
    try:
        value = float(text)
    except ValueError:
        raise ShadeLabError(f"{flag} '{text}': expected a number > 0, e.g. 0.01") from None
    return check_budget(value, flag)


def auto_tessellate(scene, shading: str, size: tuple[int, int], budget: float,
                    specular: str | None = None, max_side: int = 256) -> list[str]:
    """Set every round sphere's subdivision level to the cheapest that meets ``budget``.

    Each sphere is measured alone against its exact per-pixel reference (see
    :mod:`shadelab.studies.shading_study`) at the render's aspect, capped at ``max_side`` pixels;
    the cost is the triangle count. Returns one report line per sphere.
    """
    from shadelab.studies.shading_study import COLUMNS, LEVELS, measure_sphere, sphere_of

    budget = check_budget(budget)
    scale = min(1.0, max_side / max(size))
    probe = (max(8, round(size[0] * scale)), max(8, round(size[1] * scale)))
    lines = []
    for index, obj in enumerate(scene.objects):
        if sphere_of(obj) is None:
            continue
        rows = measure_sphere(scene, index, shading, probe, LEVELS, specular, repeats=1)
        records = [dict(zip(COLUMNS, row, strict=True)) for row in rows]
        choice = choose_setting(front_from_rows(records, ("level",), "triangles"), budget)
        obj.subdivisions = int(choice.point.setting["level"])
        verdict = "<=" if choice.met else "> (best reachable)"
        lines.append(f"auto quality: objects.{index} ({obj.name or obj.shape}) subdivisions "
                     f"{obj.subdivisions}: relMSE {choice.point.error:.3g} {verdict} {budget:g}")
    if not lines:
        lines.append("auto quality: no round sphere to tessellate (only spheres have an exact "
                     "reference); rendering as the preset says")
    return lines
