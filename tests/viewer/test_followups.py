"""CLI follow-ups (shadelab.ui.followups) without a window: when ``--frames`` lets the viewer
quit, what ``--show-radiosity`` does once the job ends, ``--gallery`` with a bad name."""

from __future__ import annotations

from types import SimpleNamespace

from shadelab.lab.state import AppState
from shadelab.scene import load_preset
from shadelab.ui.followups import FollowUps, ViewerOptions, open_gallery_case


def _state(**job):
    state = AppState.from_scene(load_preset("cornell"), "cornell")
    runner = {"running": False, "started": True, "version": 0, **job}
    state.offline.runner = SimpleNamespace(**runner)
    state.offline.version = 0
    return state


def test_frames_quit_at_the_count_when_nothing_is_asked_for():
    follow, state = FollowUps(ViewerOptions(frames=3)), _state()
    quits = []
    for frame in range(5):
        state.frame = frame
        quits.append(follow.end_frame(state))
    assert quits == [False, False, False, True, True]
    assert not FollowUps(ViewerOptions()).end_frame(state)  # no --frames: run until closed


def test_frames_count_after_the_job_and_then_the_job_is_followed_up():
    follow = FollowUps(ViewerOptions(frames=2, job="radiosity", show_radiosity=True))
    state = _state(running=True)
    state.frame, state.offline.radiosity_soup = 10, object()
    assert not follow.end_frame(state) and not state.offline.show_radiosity  # still running
    state.offline.runner.running = False
    state.offline.version = -1                  # its last image not uploaded yet
    assert not follow.end_frame(state)
    state.offline.version = 0
    assert follow.end_frame(state) and state.offline.show_radiosity and follow.job_followed_up


def test_a_bad_gallery_name_is_an_error_naming_the_cases():
    state = _state()
    open_gallery_case(state, "no-such-case")
    assert state.error.startswith("--gallery 'no-such-case': expected one of")
