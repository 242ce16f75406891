"""The Studies panel (speed-vs-accuracy charts drawn live with ImPlot) and the Failure gallery.

The logic (running a study off the UI thread, plot series, auto quality, opening a case) is in
:mod:`shadelab.lab.studies`; this module only draws it.
"""

from __future__ import annotations

import time

import numpy as np
from imgui_bundle import imgui, implot

from shadelab.lab.state import AppState
from shadelab.lab.studies import (
    StudyRun,
    auto_quality_line,
    cell,
    offline_job_label,
    offline_job_of,
    open_case,
    plot_series,
    study_front,
)
from shadelab.ui import panels
from shadelab.ui.layout import plot_size

SPINNER = "|/-\\"
PLOT_LINES = 14.0   # plot height in text lines (grows with the font)
TABLE_HEIGHT = 150
FRONT_COLOR = imgui.ImVec4(0.85, 0.85, 0.85, 0.9)


def study_run(state: AppState) -> StudyRun:
    if state.studies.run is None:
        state.studies.run = StudyRun()
    return state.studies.run


def start_study(state: AppState, name: str, quick: bool = True) -> None:
    """Start a study by name (the panel's button, ``--study NAME``)."""
    from shadelab.studies import STUDIES

    names = [n for n, _ in STUDIES]
    if name not in names:
        state.error = f"--study '{name}': expected one of {', '.join(names)}"
        return
    state.studies.index = names.index(name)
    study_run(state).start(name, quick)


# ---------------------------------------------------------------- studies


def _wrapped(text: str, color=None) -> None:
    imgui.push_text_wrap_pos(0.0)
    if color is None:
        imgui.text_unformatted(text)
    else:
        imgui.text_colored(color, text)
    imgui.pop_text_wrap_pos()


def _draw_chart(table, front: bool) -> int:
    """The table's chart; returns the number of points drawn."""
    if not implot.begin_plot(f"{table.title}##study", plot_size(PLOT_LINES)):
        return 0
    drawn = 0
    implot.setup_axes(table.x, table.y, implot.AxisFlags_.auto_fit, implot.AxisFlags_.auto_fit)
    if table.log_x:
        implot.setup_axis_scale(implot.ImAxis_.x1, implot.Scale_.log10)
    if table.log_y:
        implot.setup_axis_scale(implot.ImAxis_.y1, implot.Scale_.log10)
    implot.setup_legend(implot.Location_.east, implot.LegendFlags_.outside)
    for name, xs, ys, labels in plot_series(table):
        if not xs:
            continue
        spec = implot.Spec()
        spec.marker = implot.Marker_.circle
        spec.marker_size = 3.0
        x, y = np.asarray(xs, np.float64), np.asarray(ys, np.float64)
        drawn += len(x)
        if name.replace(".", "", 1).isdigit() and table.group:
            name = f"{table.group} {name}"  # "spp 4" rather than a bare "4"
        if table.lines:
            implot.plot_line(name, x, y, spec)
        else:
            implot.plot_scatter(name, x, y, spec)
        for px, py, text in zip(xs, ys, labels, strict=True):
            if text:
                implot.plot_text(text, px, py, imgui.ImVec2(6, -6))
    if front:
        from shadelab.studies.autoquality import pareto_front

        best = pareto_front(study_front(table))
        if len(best) > 1:
            series = {n: ys for n, _, ys, _ in plot_series(table)}
            positive = [v for ys in series.values() for v in ys if v > 0]
            floor = min(positive) if positive else 1e-12
            spec = implot.Spec()
            spec.line_color = FRONT_COLOR
            spec.line_weight = 1.0
            implot.plot_stairs("Pareto", np.array([p.cost for p in best], np.float64),
                               np.array([max(p.error, floor) if table.log_y else p.error
                                         for p in best], np.float64), spec)
    implot.end_plot()
    return drawn


def _draw_rows(table) -> None:
    columns = list(table.columns)
    flags = (imgui.TableFlags_.borders | imgui.TableFlags_.row_bg | imgui.TableFlags_.scroll_y
             | imgui.TableFlags_.scroll_x | imgui.TableFlags_.sizing_fixed_fit)
    if not imgui.begin_table("study_rows", len(columns), flags, imgui.ImVec2(0, TABLE_HEIGHT)):
        return
    imgui.table_setup_scroll_freeze(0, 1)
    for name in columns:
        imgui.table_setup_column(name)
    imgui.table_headers_row()
    for row in table.rows:
        imgui.table_next_row()
        for value in row:
            imgui.table_next_column()
            imgui.text_unformatted(cell(value))
    imgui.end_table()


def draw_studies_panel(state: AppState) -> bool:
    """Pick a study, run it off the UI thread, plot its result; auto quality on its front."""
    from shadelab.studies import STUDIES

    run = study_run(state)
    run.poll()
    labels = [f"{name}: {title}" for name, title in STUDIES]
    _, state.studies.index = imgui.combo("Study", state.studies.index, labels)
    name = STUDIES[state.studies.index][0]
    imgui.begin_disabled(run.running)
    if imgui.button("Run (quick)"):
        start_study(state, name, quick=True)
    imgui.same_line()
    if imgui.button("Run (full)"):
        start_study(state, name, quick=False)
    imgui.end_disabled()
    imgui.same_line()
    imgui.begin_disabled(not run.running)
    if imgui.button("Cancel##study"):
        run.cancel()
    imgui.end_disabled()
    if run.running:
        spin = SPINNER[int(time.perf_counter() * 8) % len(SPINNER)]
        imgui.text_wrapped(f"{spin} running the {run.name} study "
                   f"({'quick' if run.quick else 'full'})...  {run.elapsed:.1f} s")
    elif run.error:
        _wrapped(f"{run.name} failed: {run.error}", panels.ERROR_COLOR)
    result = run.result
    if result is None:
        if not run.running:
            imgui.push_style_color(imgui.Col_.text, panels.DIM_COLOR)
            imgui.text_wrapped("Press Run to measure speed against accuracy.")
            imgui.pop_style_color()
        return False
    tables = [("main", result), *result.extra.items()]
    done = f", done in {run.elapsed:.1f} s" if not run.running and run.name == result.name \
        else ""
    imgui.text_wrapped(f"{result.name}: {len(result.rows)} rows{done}")
    if len(tables) > 1:
        imgui.same_line()
        imgui.text("  chart:")
        for i, (key, _) in enumerate(tables):
            imgui.same_line()
            if imgui.radio_button(f"{key}##chart", state.studies.chart == i):
                state.studies.chart = i
    state.studies.chart = min(state.studies.chart, len(tables) - 1)
    table = tables[state.studies.chart][1]
    state.studies.plotted = _draw_chart(table, front=table is result)
    if study_front(result):
        _, state.studies.budget = imgui.slider_float(
            "error budget", state.studies.budget, 1e-5, 1.0, "%.2g", imgui.SliderFlags_.logarithmic)
        _wrapped(auto_quality_line(result, state.studies.budget), panels.OK_COLOR)
    _draw_rows(table)
    for note in result.notes:
        _wrapped(note, panels.DIM_COLOR)
    return False


# ---------------------------------------------------------------- failure gallery


def draw_gallery_panel(state: AppState) -> bool:
    """List the failure gallery; the selected case's explanation; open it in the viewer."""
    from shadelab.studies.gallery import GALLERY
    from shadelab.ui.offline import start_job_by_label

    if imgui.begin_list_box("##cases", imgui.ImVec2(-1, 150)):
        for i, case in enumerate(GALLERY):
            selected = state.studies.gallery_index == i
            if imgui.selectable(f"{case.name}  ({case.method})", selected)[0]:
                state.studies.gallery_index = i
        imgui.end_list_box()
    if not 0 <= state.studies.gallery_index < len(GALLERY):
        imgui.text_colored(panels.DIM_COLOR, "Select a case to see what fails and why.")
        return False
    case = GALLERY[state.studies.gallery_index]
    imgui.text_wrapped(case.name)
    overrides = " ".join(f"--set {o}" for o in case.overrides)
    _wrapped(f"preset {case.preset} {overrides}   method {case.method}", panels.DIM_COLOR)
    imgui.separator()
    _wrapped(case.explanation)
    imgui.separator()
    _wrapped(f"test: {case.test_name}", panels.DIM_COLOR)
    if imgui.button("Open in viewer"):
        open_case(state, case)
    job = offline_job_of(case)
    if job:
        imgui.same_line()
        imgui.begin_disabled(state.offline.runner.running)
        if imgui.button("Run offline job") and open_case(state, case):
            start_job_by_label(state, job)
        imgui.end_disabled()
        _wrapped(f"shown by the {offline_job_label(case)} offline renderer (Offline render "
                 "panel)",
                 panels.DIM_COLOR)
    if state.studies.gallery_opened == case.name and not state.error:
        imgui.text_colored(panels.OK_COLOR, f"open: {state.scene.name or case.preset}, "
                           f"{state.scene.render.shading} shading")
    if state.error:
        _wrapped(f"Error: {state.error}", panels.ERROR_COLOR)
    return False
