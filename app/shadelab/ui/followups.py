"""Command-line follow-ups of ``shadelab view``: what ``--probe``, ``--focus``, ``--gallery``,
``--study``, ``--job`` and ``--pipeline`` start once the window is up, what ``--show-radiosity``
and ``--ray-tree`` do once the job ends, when ``--frames`` lets the viewer quit (after the job,
the pipeline and the study are done) and the ``--screenshot`` written at exit.

The Viewer (:mod:`shadelab.ui.app`) holds one :class:`FollowUps`; no GL here.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

from shadelab.lab.state import AppState
from shadelab.ui import pipelines


@dataclass
class ViewerOptions:
    """Command-line extras: scripted frames, screenshots, tests and the bench."""

    frames: int = 0                       # quit after this many frames (0: run until closed)
    screenshot: str = ""                  # whole-window PNG written at exit
    window_size: tuple[int, int] = (1600, 900)
    probe: tuple[int, int] | None = None  # viewport pixel probed at start
    job: str = ""                         # offline job started at start (label prefix)
    bench_json: str = ""                  # frame times written here at exit
    autosave: bool = True
    show_radiosity: bool = False          # once a radiosity job ends, show its solution
    ray_tree: tuple[int, int] | None = None  # once a Whitted job ends, trace this pixel's tree
    focus: str = ""                       # dock windows brought to front at start (a,b,...)
    study: str = ""                       # study run (quick) at start; --frames counts after it
    gallery: str = ""                     # failure-gallery case selected and opened at start
    fullscreen: bool = False              # open fullscreen at the monitor's resolution
    maximized: bool = False               # open maximized (no --window given)
    pipeline: str = ""                    # viewport pipeline at start (shadelab.ui.pipelines)
    test_function: Callable | None = None  # immapp.testing test body (GUI tests)
    page_down: int = 0                    # bench: PageDown this many times, each once the
    #                                       lesson step (and its prefetch) has settled


def lesson_offline(state: AppState) -> bool:
    """A lesson's current step shows an offline pipeline (``--frames`` counts after its job)."""
    run = state.walk.lesson
    return run is not None and run.step is not None and run.step.pipeline in pipelines.OFFLINE


def prefetch_settled(state: AppState) -> bool:
    """The next step's prefetch (when on and wanted) has finished."""
    from shadelab.lab.prefetch import next_offline

    if not state.walk.prefetch_enabled or next_offline(state.walk.lesson,
                                                       pipelines.OFFLINE) is None:
        return True
    pf = state.walk.prefetch
    return pf is not None and pf.record is not None and pf.record.done_s is not None


def open_gallery_case(state: AppState, name: str) -> None:
    """``--gallery NAME``: select the failure-gallery case and open it in the viewer."""
    from shadelab.lab.studies import open_case
    from shadelab.studies.gallery import GALLERY

    names = [case.name for case in GALLERY]
    if name not in names:
        state.error = f"--gallery '{name}': expected one of {', '.join(names)}"
        return
    state.studies.gallery_index = names.index(name)
    open_case(state, GALLERY[state.studies.gallery_index])


@dataclass
class FollowUps:
    options: ViewerOptions
    job_followed_up: bool = False
    study_done_at: int = 0             # frame the --study run ended
    page_down_s: float | None = None   # bench: when the (first) scripted PageDown happened
    page_downs_s: list = field(default_factory=list)   # bench: every scripted PageDown
    settled_at: int = 0                # bench: frame the step (and its prefetch) settled
    page_down_at: int = 0              # bench: frame of that PageDown

    def start(self, state: AppState, dockable_windows: list) -> None:
        """Once the window (and its GL) is up: the start-up requests of the command line."""
        options = self.options
        if options.probe is not None:
            state.probe.pixel, state.probe.requested = options.probe, True
        if options.focus:
            from shadelab.ui.layout import focus_windows

            focus_windows(dockable_windows, options.focus)
        if options.gallery:
            open_gallery_case(state, options.gallery)
        if options.study:
            from shadelab.ui.studies_panel import start_study

            start_study(state, options.study)
        if options.job:
            from shadelab.ui.offline import start_job_by_label

            start_job_by_label(state, options.job)
        if options.pipeline:
            pipelines.set_pipeline(state, options.pipeline)

    def waiting(self, state: AppState) -> bool:
        """A job, pipeline or study the command line started is not done yet (``--frames``
        counts after it; the study's plot fits its axes over a few frames more)."""
        options = self.options
        runner = state.offline.runner
        waiting = bool(options.job) and (runner.running or not runner.started
                                         or state.offline.version != runner.version)
        waiting = waiting or bool((options.pipeline or lesson_offline(state))
                                  and pipelines.busy(state))
        if options.page_down and (len(self.page_downs_s) < int(options.page_down)
                                  or state.frame < self.page_down_at + 3):
            self.press_page_down(state)
            waiting = True    # (after it: the new step's job is polled on the next frame)
        if state.studies.run is not None:
            state.studies.run.poll()  # also while the Studies tab is hidden
            if options.study and not self.study_done_at and not state.studies.run.running:
                self.study_done_at = state.frame
            waiting = waiting or bool(options.study and (
                state.studies.run.running
                or state.frame < self.study_done_at + min(options.frames, 10)))
        return waiting

    def press_page_down(self, state: AppState) -> bool:
        """Bench (``--bench-page-down [N]``): PageDown once the step's job and the next
        step's prefetch are done and a few frames have passed, N times (the lesson walked
        without a restart); True once every press is done."""
        import time

        from shadelab.lab.lesson import next_step

        if len(self.page_downs_s) >= int(self.options.page_down):
            return True
        if self.page_downs_s and state.frame < self.page_down_at + 5:
            return False     # the new step's job has not been asked for yet
        view = state.view.pipeline_view
        idle = view is None or view.runner is None or not view.runner.running  # (warm-up)
        settled = idle and state.frame >= 10 and not pipelines.busy(state) \
            and not (lesson_offline(state) and state.frame < 5) and prefetch_settled(state)
        if not settled:
            self.settled_at = 0
            return False
        if not self.settled_at:
            self.settled_at = state.frame
        if state.frame < self.settled_at + 5:
            return False
        now = pipelines.since_start(time.perf_counter())
        self.page_down_s = now if self.page_down_s is None else self.page_down_s
        self.page_downs_s.append(now)
        self.page_down_at, self.settled_at = state.frame, 0
        next_step(state)
        return len(self.page_downs_s) >= int(self.options.page_down)

    def bench_extra(self) -> dict:
        return {} if self.page_down_s is None else {"page_down_s": self.page_down_s,
                                                    "page_downs_s": list(self.page_downs_s)}

    def end_frame(self, state: AppState, frame0: int = 0) -> bool:
        """Once a frame: the after-job requests; True when ``--frames`` says quit now
        (``--frames`` frames after ``frame0``: the bench counts from a settled viewer)."""
        waiting = self.waiting(state)
        if self.options.job and not waiting and not self.job_followed_up:
            self.job_followed_up = True
            self.follow_up_job(state)
        return bool(self.options.frames) and state.frame - frame0 >= self.options.frames \
            and not waiting

    def follow_up_job(self, state: AppState) -> None:
        """The command line's after-job requests: radiosity in the viewport, a ray tree."""
        if self.options.show_radiosity and state.offline.radiosity_soup is not None:
            state.offline.show_radiosity = True
        if self.options.ray_tree is not None and state.offline.scene is not None:
            from shadelab.ui.offline import trace_tree

            trace_tree(state, self.options.ray_tree)


def write_window_screenshot(path: str) -> None:
    """``--screenshot PATH``: the whole window's last frame, written after the window closed."""
    from imgui_bundle import hello_imgui
    from PIL import Image

    image = hello_imgui.final_app_window_screenshot()
    Image.fromarray(image).save(path)
    print(f"wrote {path} ({image.shape[1]}x{image.shape[0]})")
