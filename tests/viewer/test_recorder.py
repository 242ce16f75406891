"""The frame recorder (shadelab.lab.recorder): bench phases, per-phase frame figures, the
``--bench-json`` file. No window: frames are fed by hand."""

from __future__ import annotations

import json

import pytest

from shadelab.lab.recorder import (
    IDLE,
    INTERACTIVE,
    REDRAW,
    SETTLING,
    WARM_UP_FRAMES,
    FrameRecorder,
)


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


def test_breakdown_parts_are_non_negative_and_sum_to_at_most_the_frame(tmp_path):
    """The bench's breakdown of a frame: each part's main-thread CPU time, a nested part taken
    out of the one around it, and the rest of the frame's process CPU time as other_cpu_ms;
    parts are disjoint intervals of the frame, so they never sum to more than it."""
    import time

    from shadelab.lab.recorder import PARTS

    def burn(seconds: float) -> None:
        end = time.thread_time() + seconds
        while time.thread_time() < end:
            pass

    rec = FrameRecorder(viewport_shown=True, breakdown=True)
    rec.frame_swapped()
    n = WARM_UP_FRAMES + 6
    for frame in range(2 * n):
        redraw = frame >= n
        rec.begin("gui")
        burn(0.002)
        if redraw:
            with rec.part("scene"):
                burn(0.003)
                with rec.part("readback"):
                    burn(0.001)
        rec.end("gui")
        rec.begin("gui_render")
        burn(0.001)
        rec.redrawn = redraw
        rec.frame_swapped()   # closes gui_render
    assert len(rec.part_cpu) == len(rec.frame_times) and rec._open == []
    report = rec.report((1280, 720))
    for phase in ("idle", "redraw"):
        parts = report[f"{phase}_breakdown"]
        assert set(parts["cpu_ms"]) == set(PARTS) == set(parts["wall_ms"])
        assert all(v >= 0.0 for v in parts["cpu_ms"].values())
        assert all(v >= 0.0 for v in parts["wall_ms"].values())
        assert parts["other_cpu_ms"] >= 0.0
        frame_cpu = parts["frame_cpu_ms"]
        assert sum(parts["cpu_ms"].values()) <= frame_cpu * 1.05 + 0.5
        assert sum(parts["wall_ms"].values()) <= parts["frame_wall_ms"] * 1.05 + 0.5
        assert parts["parts_over_frame_cpu_max"] <= 1.0 + 1e-6
        assert parts["frames"] == n - WARM_UP_FRAMES
    idle, redraw = report["idle_breakdown"]["cpu_ms"], report["redraw_breakdown"]["cpu_ms"]
    assert idle["scene"] == 0.0 and idle["readback"] == 0.0
    # nested parts are exclusive: gui ~2 ms, scene ~3 ms, readback ~1 ms, gui_render ~1 ms
    assert redraw["gui"] == pytest.approx(2.0, abs=1.0)
    assert redraw["scene"] == pytest.approx(3.0, abs=1.0)
    assert redraw["readback"] == pytest.approx(1.0, abs=0.7)
    assert redraw["gui_render"] == pytest.approx(1.0, abs=0.7)


def test_breakdown_is_off_outside_the_bench():
    rec = FrameRecorder(viewport_shown=True)
    rec.begin("gui")
    rec.end("gui")
    rec.frame_swapped()
    assert rec.part_cpu == [] and "idle_breakdown" not in rec.report((640, 480))


def test_settling_frames_are_in_no_phase_and_the_settle_time_is_reported(tmp_path):
    """The bench's frames before the viewer settled (the start-up warm-up on the other core)
    time the warm-up: they must not enter the idle median."""
    rec = FrameRecorder(viewport_shown=True)
    n = WARM_UP_FRAMES + 4
    rec.settling = True
    for _ in range(n):
        rec.frame_swapped()
    rec.settling = False
    rec.settled = rec.first_frame + 2.5
    for _ in range(n):
        rec.frame_swapped()
    assert rec.redraw_flags == [SETTLING] * n + [IDLE] * n
    # settling frames last 100 ms, the settled idle ones 10 ms
    rec.frame_times = [0.1 * i for i in range(n)] + [0.1 * (n - 1) + 0.01 * (i + 1)
                                                      for i in range(n)]
    path = tmp_path / "viewer.json"
    rec.write(str(path), (1280, 720), {})
    report = json.loads(path.read_text())
    assert report["idle_frame_ms_median"] == pytest.approx(10.0)
    assert report["settled_after_first_frame_s"] == pytest.approx(2.5)
