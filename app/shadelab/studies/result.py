"""The data a study hands to a chart: named columns, rows, and which columns to plot."""

from __future__ import annotations

import csv
import os
import time
from dataclasses import dataclass, field
from pathlib import Path


@dataclass
class StudyResult:
    """One study's measurements, ready to plot.

    Attributes
    ----------
    name : short id, also the CSV/PNG file stem ("shading", "raytrace", ...)
    title : chart title
    columns : column names; every row has one value per column
    rows : the measurements (numbers or short strings)
    x, y : the columns of the main chart (e.g. "time_ms" against "rmse")
    group : the column whose values make separate series (e.g. "method")
    label : the column annotating each point (e.g. "level"), or ""
    log_x, log_y : axis scales of the main chart
    lines, front : join each series' points; draw the Pareto front (cost x, error y)
    notes : lines worth printing next to the chart (reference used, machine, skips)
    extra : further named tables (e.g. a convergence curve per solver): name -> StudyResult
    """

    name: str
    title: str
    columns: list[str]
    rows: list[list] = field(default_factory=list)
    x: str = ""
    y: str = ""
    group: str = ""
    label: str = ""
    log_x: bool = True
    log_y: bool = True
    lines: bool = True           # join a series' points (False: a scatter of unrelated cases)
    front: bool = True           # draw the Pareto front of (x, y) over all rows
    notes: list[str] = field(default_factory=list)
    extra: dict[str, "StudyResult"] = field(default_factory=dict)

    def column(self, name: str, rows: list[list] | None = None) -> list:
        """The values of one column (of ``rows``, default all rows)."""
        index = self.columns.index(name)
        return [row[index] for row in (self.rows if rows is None else rows)]

    def series(self) -> dict[str, list[list]]:
        """Rows split by the ``group`` column, in first-seen order (one series each)."""
        if not self.group:
            return {self.name: list(self.rows)}
        index = self.columns.index(self.group)
        out: dict[str, list[list]] = {}
        for row in self.rows:
            out.setdefault(str(row[index]), []).append(row)
        return out

    def records(self) -> list[dict]:
        """Rows as dictionaries keyed by column name."""
        return [dict(zip(self.columns, row, strict=False)) for row in self.rows]

    def write_csv(self, path: str | Path) -> None:
        with open(path, "w", newline="", encoding="utf-8") as f:
            writer = csv.writer(f)
            writer.writerow(self.columns)
            for row in self.rows:
                writer.writerow([_cell(v) for v in row])


def _cell(value):
    if isinstance(value, float):
        return f"{value:.6g}"
    return value


def study_clock() -> float:
    """Seconds of CPU time of this process, all threads (llvmpipe, Embree, numpy, numba).

    The studies time work with it rather than the wall clock: on a shared machine other jobs
    add wall time at random, never CPU time of ours. ``SHADELAB_STUDY_CLOCK=wall`` switches to
    the wall clock (for a real GPU, whose work the process's CPU time does not see).
    """
    if os.environ.get("SHADELAB_STUDY_CLOCK", "cpu") == "wall":
        return time.perf_counter()
    return time.process_time()
