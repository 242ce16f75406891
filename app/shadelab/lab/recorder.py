"""The frame recorder: when each frame reached the screen, its CPU time, whether it re-rendered
the scene, and the ``--bench-json`` report made of them (``shadelab bench --only viewer``).

No GL and no GUI: the Viewer (:mod:`shadelab.ui.app`) calls :meth:`FrameRecorder.frame_swapped`
after each swap and :meth:`FrameRecorder.write` at exit.
"""

from __future__ import annotations

import json
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

WARM_UP_FRAMES = 5  # skipped in each phase's figures

IDLE, REDRAW, INTERACTIVE = 0, 1, 2  # what a frame did: GUI only, full redraw, drag redraw
PHASES = (("idle", IDLE), ("redraw", REDRAW), ("interactive", INTERACTIVE))


@dataclass
class FrameRecorder:
    started: float = field(default_factory=time.perf_counter)
    first_frame: float = 0.0           # perf_counter of the first frame showing the viewport
    frame_times: list = field(default_factory=list)
    cpu_times: list = field(default_factory=list)
    redraw_flags: list = field(default_factory=list)
    force_redraw: bool = False         # the bench's later phases: re-render every frame
    force_interactive: bool = False    # the bench's last phase: as if a slider were dragged
    redrawn: bool = False              # this frame re-rendered the scene
    viewport_shown: bool = False       # the viewport window has drawn (first_frame counts)

    def set_phase(self, frame: int, frames: int) -> None:
        """The bench's phases over ``frames`` frames: idle (GUI only), full-resolution redraw,
        interactive (drag) redraw."""
        third = frames // 3
        self.force_redraw = frame >= third
        self.force_interactive = frame >= 2 * third

    def frame_swapped(self) -> bool:
        """After the frame is on screen: its time, CPU time and whether it re-rendered the
        scene. The first frame counts once the viewport has drawn (the very first frames
        only lay out the dock space and show no scene). True on that first frame."""
        now = time.perf_counter()
        first = not self.first_frame and self.viewport_shown
        if first:
            self.first_frame = now
        self.frame_times.append(now)
        self.cpu_times.append(time.process_time())
        flag = IDLE if not self.redrawn else (INTERACTIVE if self.force_interactive else REDRAW)
        self.redraw_flags.append(flag)
        self.redrawn = False
        return first

    def report(self, window_size: tuple[int, int]) -> dict:
        """Frame times of idle frames (GUI only) and of frames that re-render the scene."""
        times = np.diff(np.asarray(self.frame_times)) * 1000.0
        flags = np.asarray(self.redraw_flags[1:])
        report = {"first_frame_s": self.first_frame_since_start(),
                  "frames": len(self.frame_times), "window": list(window_size)}
        cpu = np.diff(np.asarray(self.cpu_times)) * 1000.0
        for name, flag in PHASES:
            select = flags == flag
            picked = times[select][WARM_UP_FRAMES:]
            picked_cpu = cpu[select][WARM_UP_FRAMES:]
            if len(picked):
                report[f"{name}_frame_ms_median"] = float(np.median(picked))
                report[f"{name}_frame_ms_max"] = float(np.max(picked))
                report[f"{name}_cpu_ms_median"] = float(np.median(picked_cpu))
        return report

    def write(self, path: str, window_size: tuple[int, int], extra: dict) -> None:
        """The ``--bench-json`` file: :meth:`report` plus ``extra`` (the pipelines' jobs)."""
        report = self.report(window_size)
        report.update(extra)
        Path(path).write_text(json.dumps(report), encoding="utf-8")

    def first_frame_since_start(self) -> float:
        """Seconds from process start to the first frame (Linux /proc; else since start)."""
        try:
            ticks = os.sysconf("SC_CLK_TCK")
            start = int(Path("/proc/self/stat").read_text().rsplit(")", 1)[1].split()[19]) / ticks
            uptime_now = float(Path("/proc/uptime").read_text().split()[0])
            return uptime_now - start - (time.perf_counter() - self.first_frame)
        except (OSError, ValueError, IndexError):
            return self.first_frame - self.started
