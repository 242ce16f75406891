"""AppState's typed sub-states (shadelab.lab.state): the panels' old attribute names read and
write the sub-state fields; no name is claimed twice; defaults are the sub-states' own."""

from __future__ import annotations

from dataclasses import fields

from shadelab.lab.state import SUB_STATES, AppState
from shadelab.scene import load_preset


def _state() -> AppState:
    return AppState.from_scene(load_preset("cornell"), "cornell")


def test_no_field_name_is_claimed_twice():
    own = {f.name for f in fields(AppState)}
    seen: set[str] = set()
    for cls in SUB_STATES.values():
        names = {f.name for f in fields(cls)}
        assert not names & own and not names & seen, names & (own | seen)
        seen |= names


def test_old_names_read_and_write_the_sub_states():
    state = _state()
    for part, cls in SUB_STATES.items():
        sub = getattr(state, part)
        assert isinstance(sub, cls)
        for f in fields(cls):
            assert getattr(state, f.name) is getattr(sub, f.name)
            marker = object()
            setattr(state, f.name, marker)
            assert getattr(sub, f.name) is marker
    assert not hasattr(state, "__dict__") or "compare" not in vars(state)


def test_from_scene_keeps_the_defaults_and_accepts_old_names():
    state = AppState.from_scene(load_preset("cornell"), "cornell", compare=True, job_size=64)
    assert state.view_state.compare and state.job_state.job_size == 64
    assert state.job is not None and state.probe is None and state.lesson is None
    other = _state()
    assert other.view_state is not state.view_state  # one sub-state per AppState
    other.mark_edited()
    assert other.probe_state.probe_requested is False  # no probed pixel
    other.probe_pixel = (3, 4)
    other.mark_edited()
    assert other.probe_state.probe_requested is True
