"""One bounded memo for the raster passes' per-geometry answers (closed? convex? wound
outward? which casters hold nothing?): computed once per key, the table started again when it
outgrows its limit (geometry edited many times, a slider sweeping a light)."""

from __future__ import annotations

from typing import Callable, TypeVar

T = TypeVar("T")
_MISSING = object()


def memoized(table: dict, key, compute: Callable[[], T], limit: int) -> T:
    """``table[key]``, from ``compute()`` the first time (None is a value too); ``table`` is
    cleared first when it already holds ``limit`` entries."""
    value = table.get(key, _MISSING)
    if value is _MISSING:
        if len(table) >= limit:
            table.clear()
        value = table[key] = compute()
    return value
