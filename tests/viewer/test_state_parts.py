"""AppState's typed sub-states (shadelab.lab.state): each is used by its own name
(``state.view.compare``, ``state.probe.pixel``...); only the flat names listed as remaining for
the pipelines merge still reach into them, and no other flat name is left."""

from __future__ import annotations

from dataclasses import fields

from shadelab.lab.state import REMAINING_FLAT_NAMES, SUB_STATES, AppState
from shadelab.scene import load_preset


def _state() -> AppState:
    return AppState.from_scene(load_preset("cornell"), "cornell")


def test_the_sub_states_are_appstate_fields_of_their_own_type():
    own = {f.name: f for f in fields(AppState)}
    state = _state()
    for part, cls in SUB_STATES.items():
        assert part in own
        assert isinstance(getattr(state, part), cls)
        assert getattr(state, part) is not getattr(_state(), part)  # one per AppState


def test_only_the_listed_flat_names_remain():
    """A sub-state field is not an AppState attribute unless the pipelines merge still needs
    it; each remaining name reads and writes its sub-state's field."""
    state = _state()
    for part, cls in SUB_STATES.items():
        for f in fields(cls):
            flat = [n for n, target in REMAINING_FLAT_NAMES.items() if target == (part, f.name)]
            if not flat and f.name not in SUB_STATES:
                assert not hasattr(state, f.name) or f.name in {g.name for g in fields(AppState)}
    for name, (part, field_name) in REMAINING_FLAT_NAMES.items():
        assert field_name in {f.name for f in fields(SUB_STATES[part])}, name
        sub = getattr(state, part)
        assert getattr(state, name) is getattr(sub, field_name)
        marker = object()
        setattr(state, name, marker)
        assert getattr(sub, field_name) is marker
    assert not hasattr(state, "probe_pixel") and not hasattr(state, "study_index")
    assert not hasattr(state, "focus_request") and not hasattr(state, "show_gizmos")


def test_from_scene_keeps_the_defaults():
    state = AppState.from_scene(load_preset("cornell"), "cornell", status="hello")
    assert state.status == "hello" and not state.view.compare and state.offline.size == 256
    assert state.offline.runner is not None and state.probe.result is None
    assert state.walk.lesson is None and state.studies.run is None
    other = _state()
    other.mark_edited()
    assert other.probe.requested is False  # no probed pixel
    other.probe.pixel = (3, 4)
    other.mark_edited()
    assert other.probe.requested is True
