"""The frame recorder (shadelab.lab.recorder): bench phases, per-phase frame figures, the
``--bench-json`` file. No window: frames are fed by hand."""

from __future__ import annotations

import json

import pytest

from shadelab.lab.recorder import IDLE, INTERACTIVE, REDRAW, WARM_UP_FRAMES, FrameRecorder


def test_bench_phases_split_the_frames_in_thirds():
    rec = FrameRecorder()
    seen = []
    for frame in range(9):
        rec.set_phase(frame, 9)
        seen.append((rec.force_redraw, rec.force_interactive))
    assert seen == [(False, False)] * 3 + [(True, False)] * 3 + [(True, True)] * 3


def test_first_frame_counts_once_the_viewport_has_drawn():
    rec = FrameRecorder()
    assert rec.frame_swapped() is False and rec.first_frame == 0.0  # dock space only
    rec.viewport_shown = True
    assert rec.frame_swapped() is True and rec.first_frame > 0.0
    assert rec.frame_swapped() is False
    assert rec.first_frame_since_start() > 0.0


def test_each_frame_is_flagged_idle_redraw_or_interactive():
    rec = FrameRecorder()
    for redrawn, interactive in ((False, False), (True, False), (True, True), (False, True)):
        rec.redrawn, rec.force_interactive = redrawn, interactive
        rec.frame_swapped()
        assert rec.redrawn is False  # cleared for the next frame
    assert rec.redraw_flags == [IDLE, REDRAW, INTERACTIVE, IDLE]


def test_report_has_the_figures_of_each_phase_after_its_warm_up(tmp_path):
    rec = FrameRecorder(viewport_shown=True)
    n = WARM_UP_FRAMES + 4
    for flag in [IDLE] + [IDLE] * n + [REDRAW] * n:
        rec.redrawn = flag != IDLE
        rec.frame_swapped()
    # frame i (after the first) lasts 10 ms when idle, 30 ms when redrawn
    t = 0.0
    rec.frame_times = [t]
    for flag in rec.redraw_flags[1:]:
        t += 0.01 if flag == IDLE else 0.03
        rec.frame_times.append(t)
    path = tmp_path / "viewer.json"
    rec.write(str(path), (1280, 720), {"jobs": []})
    report = json.loads(path.read_text())
    assert report["frames"] == 1 + 2 * n and report["window"] == [1280, 720]
    assert report["idle_frame_ms_median"] == pytest.approx(10.0)
    assert report["redraw_frame_ms_median"] == pytest.approx(30.0)
    assert "interactive_frame_ms_median" not in report
    assert report["jobs"] == [] and "first_frame_s" in report
