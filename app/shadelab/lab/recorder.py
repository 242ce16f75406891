"""The frame recorder: when each frame reached the screen, its CPU time, whether it re-rendered
the scene, what its CPU time went to, and the ``--bench-json`` report made of them
(``shadelab bench --only viewer``).

No GL and no GUI: the Viewer (:mod:`shadelab.ui.app`) calls :meth:`FrameRecorder.frame_swapped`
after each swap, :meth:`FrameRecorder.begin` / :meth:`FrameRecorder.end` around the parts of a
frame (the GUI build, the scene passes, read-backs, the GUI's GL draw and swap) and
:meth:`FrameRecorder.write` at exit.

The breakdown: each part is the main thread's CPU time (``time.thread_time``) and wall time in
it, a nested part's time taken out of the part around it; ``other_cpu_ms`` is the rest of the
frame's process CPU time (``time.process_time``, every thread): the GL driver's threads
(llvmpipe rasterizes there), event polling, the runner. Parts are disjoint intervals of one
frame, so they never sum to more than the frame.
"""

from __future__ import annotations

import json
import os
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

WARM_UP_FRAMES = 5  # skipped in each phase's figures

# what a frame did: GUI only, full redraw, drag redraw; SETTLING: before the bench's phases (the
# start-up warm-up still running on the other core), in no phase's figures
SETTLING, IDLE, REDRAW, INTERACTIVE = -1, 0, 1, 2
PHASES = (("idle", IDLE), ("redraw", REDRAW), ("interactive", INTERACTIVE))
# The parts of a frame's CPU time (the Viewer's hooks): the panels and dock windows built in
# Python (ImGui calls), the viewport's scene passes (the Renderer, overlays, display pass), the
# GPU work panels queued (state.gpu: renders and their read-backs), the viewer's own read-backs
# (probe, screenshot), then ImGui's draw lists rendered by its GL backend and the buffer swap.
PARTS = ("gui", "scene", "gpu_requests", "readback", "gui_render")


@dataclass
class FrameRecorder:
    started: float = field(default_factory=time.perf_counter)
    first_frame: float = 0.0           # perf_counter of the first frame showing the viewport
    first_frame_cpu: float = 0.0       # the process's CPU seconds then (every thread)
    frame_times: list = field(default_factory=list)
    cpu_times: list = field(default_factory=list)
    redraw_flags: list = field(default_factory=list)
    force_redraw: bool = False         # the bench's later phases: re-render every frame
    force_interactive: bool = False    # the bench's last phase: as if a slider were dragged
    redrawn: bool = False              # this frame re-rendered the scene
    viewport_shown: bool = False       # the viewport window has drawn (first_frame counts)
    breakdown: bool = False            # time the parts of each frame (the bench)
    settling: bool = False             # the bench's phases have not started (warm-up running)
    settled: float = 0.0               # perf_counter when they started (0: not the bench)
    part_cpu: list = field(default_factory=list)    # per frame: {part: main-thread CPU s}
    part_wall: list = field(default_factory=list)   # per frame: {part: wall s}
    _open: list = field(default_factory=list)       # [name, cpu0, wall0, child cpu, child wall]
    _cpu: dict = field(default_factory=dict)        # this frame's parts so far
    _wall: dict = field(default_factory=dict)

    # ------------------------------------------------------------ parts of a frame
    def begin(self, name: str) -> None:
        """A part of this frame starts (nested parts are taken out of the one around them)."""
        if self.breakdown:
            self._open.append([name, time.thread_time(), time.perf_counter(), 0.0, 0.0])

    def end(self, name: str) -> None:
        """The part ``name`` ends (and any part opened inside it that was left open)."""
        if not self.breakdown:
            return
        cpu_now, wall_now = time.thread_time(), time.perf_counter()
        while self._open:
            part, cpu0, wall0, child_cpu, child_wall = self._open.pop()
            cpu, wall = cpu_now - cpu0, wall_now - wall0
            self._cpu[part] = self._cpu.get(part, 0.0) + max(cpu - child_cpu, 0.0)
            self._wall[part] = self._wall.get(part, 0.0) + max(wall - child_wall, 0.0)
            if self._open:
                self._open[-1][3] += cpu
                self._open[-1][4] += wall
            if part == name:
                return

    @contextmanager
    def part(self, name: str):
        """``with recorder.part("scene"): ...``: :meth:`begin` and :meth:`end` around a block."""
        self.begin(name)
        try:
            yield
        finally:
            self.end(name)

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
        if self.breakdown and self._open:   # the GUI's draw and swap end here, inside the frame
            self.end(self._open[0][0])
        now = time.perf_counter()
        first = not self.first_frame and self.viewport_shown
        if first:
            self.first_frame = now
            self.first_frame_cpu = time.process_time()
        self.frame_times.append(now)
        self.cpu_times.append(time.process_time())
        flag = IDLE if not self.redrawn else (INTERACTIVE if self.force_interactive else REDRAW)
        flag = SETTLING if self.settling else flag
        self.redraw_flags.append(flag)
        self.redrawn = False
        if self.breakdown:
            self.part_cpu.append(self._cpu)
            self.part_wall.append(self._wall)
            self._cpu, self._wall = {}, {}
        return first

    def report(self, window_size: tuple[int, int]) -> dict:
        """Frame times of idle frames (GUI only) and of frames that re-render the scene."""
        times = np.diff(np.asarray(self.frame_times)) * 1000.0
        flags = np.asarray(self.redraw_flags[1:])
        report = {"first_frame_s": self.first_frame_since_start(),
                  "first_frame_cpu_s": self.first_frame_cpu,
                  "frames": len(self.frame_times), "window": list(window_size)}
        if self.settled and self.first_frame:   # the bench's phases began this long after
            report["settled_after_first_frame_s"] = max(self.settled - self.first_frame, 0.0)
        cpu = np.diff(np.asarray(self.cpu_times)) * 1000.0
        for name, flag in PHASES:
            select = flags == flag
            picked = times[select][WARM_UP_FRAMES:]
            picked_cpu = cpu[select][WARM_UP_FRAMES:]
            if len(picked):
                report[f"{name}_frame_ms_median"] = float(np.median(picked))
                report[f"{name}_frame_ms_max"] = float(np.max(picked))
                report[f"{name}_cpu_ms_median"] = float(np.median(picked_cpu))
                if self.breakdown and len(self.part_cpu) == len(self.frame_times):
                    frames = np.flatnonzero(select)[WARM_UP_FRAMES:] + 1
                    report[f"{name}_breakdown"] = self.breakdown_of(frames, times, cpu)
        return report

    def breakdown_of(self, frames: np.ndarray, times: np.ndarray, cpu: np.ndarray) -> dict:
        """Medians over ``frames`` (indices into the frame lists; frame i's time is
        ``times[i - 1]``) of each part's main-thread CPU and wall ms, the frame's CPU and wall
        ms, and ``other_cpu_ms``: the frame's CPU time outside every part (driver threads,
        event polling, the runner)."""
        def per_frame(table: list, part: str) -> np.ndarray:
            return np.array([table[i].get(part, 0.0) for i in frames]) * 1000.0

        cpu_parts = {part: per_frame(self.part_cpu, part) for part in PARTS}
        wall_parts = {part: per_frame(self.part_wall, part) for part in PARTS}
        frame_cpu, frame_wall = cpu[frames - 1], times[frames - 1]
        other = frame_cpu - sum(cpu_parts.values())
        return {"frames": int(len(frames)),
                "frame_cpu_ms": float(np.median(frame_cpu)),
                "frame_wall_ms": float(np.median(frame_wall)),
                "cpu_ms": {part: float(np.median(v)) for part, v in cpu_parts.items()},
                "wall_ms": {part: float(np.median(v)) for part, v in wall_parts.items()},
                "other_cpu_ms": float(np.median(np.maximum(other, 0.0))),
                "parts_over_frame_cpu_max": float(np.max(
                    (frame_cpu - other) / np.maximum(frame_cpu, 1e-9)))}

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
