"""raster.memo.memoized: one computation per key (None included), the table started again
once it holds ``limit`` entries."""

from __future__ import annotations

from shadelab.raster.memo import memoized


def test_each_key_is_computed_once_none_included_and_the_table_is_bounded():
    calls = []
    table: dict = {}

    def compute(value):
        def run():
            calls.append(value)
            return value
        return run

    assert memoized(table, "a", compute(None), 2) is None
    assert memoized(table, "a", compute("again"), 2) is None   # None was kept, not recomputed
    assert memoized(table, "b", compute(1), 2) == 1
    assert calls == [None, 1] and len(table) == 2
    assert memoized(table, "c", compute(2), 2) == 2             # full: started again
    assert table == {"c": 2}
    assert memoized(table, "a", compute(3), 2) == 3 and calls == [None, 1, 2, 3]
