"""Study results to PNG charts (matplotlib, Agg backend) with their CSV beside them."""

from __future__ import annotations

from pathlib import Path

from shadelab.studies.autoquality import FrontPoint, pareto_front
from shadelab.studies.result import StudyResult

FIGURE_DPI = 80            # keeps each PNG near 50-100 kB
PANEL_SIZE = (4.6, 3.6)    # inches per panel


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def draw_panel(ax, result: StudyResult, front: bool = True) -> None:
    """One study table on one axes: a line per group, points labelled, the Pareto front dashed."""
    from matplotlib.ticker import NullFormatter

    positive = [float(v) for v in result.column(result.y) if float(v) > 0.0]
    floor = min(positive) / 10.0 if positive else 1e-12  # zeros sit one decade below on log
    for name, rows in result.series().items():
        xs = [float(v) for v in result.column(result.x, rows)]
        ys = [max(float(v), floor) if result.log_y else float(v)
              for v in result.column(result.y, rows)]
        ax.plot(xs, ys, marker="o", markersize=4, linewidth=1.2 if result.lines else 0.0,
                label=name)
        if result.label:
            for x, y, text in zip(xs, ys, result.column(result.label, rows), strict=False):
                ax.annotate(str(text), (x, y), textcoords="offset points", xytext=(3, 3),
                            fontsize=6, alpha=0.8)
    if front and result.front and result.x and result.y:
        points = [FrontPoint({}, float(r[0]), float(r[1]))
                  for r in zip(result.column(result.x), result.column(result.y), strict=False)]
        best = pareto_front(points)
        if len(best) > 1:
            ax.step([p.cost for p in best], [max(p.error, floor) for p in best], where="post",
                    color="black", linestyle="--", linewidth=0.8, label="Pareto front")
    if result.log_x:
        ax.set_xscale("log")
        ax.xaxis.set_minor_formatter(NullFormatter())
    if result.log_y:
        ax.set_yscale("log")
    ax.set_xlabel(result.x)
    ax.set_ylabel(result.y)
    ax.set_title(result.title, fontsize=8)
    ax.grid(True, which="both", linewidth=0.3, alpha=0.5)
    ax.legend(fontsize=6)


def write_chart(result: StudyResult, out_dir: str | Path) -> list[Path]:
    """``<name>.png`` (the main panel plus one per extra table) and ``<name>.csv`` files."""
    plt = _pyplot()
    out = Path(out_dir)
    panels = [result, *result.extra.values()]
    fig, axes = plt.subplots(1, len(panels), figsize=(PANEL_SIZE[0] * len(panels), PANEL_SIZE[1]),
                             squeeze=False)
    for ax, table in zip(axes[0], panels, strict=False):
        draw_panel(ax, table, front=table is result)
    fig.tight_layout()
    written = [out / f"{result.name}.png", out / f"{result.name}.csv"]
    fig.savefig(written[0], dpi=FIGURE_DPI)
    plt.close(fig)
    result.write_csv(written[1])
    for key, table in result.extra.items():
        if table.rows is result.rows:
            continue  # the same measurements, plotted another way
        path = out / f"{result.name}-{key}.csv"
        table.write_csv(path)
        written.append(path)
    return written
