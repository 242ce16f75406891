"""AppState's typed sub-states (shadelab.lab.state): each is used by its own name
(``state.view.compare``, ``state.probe.pixel``...); no flat alias of a sub-state field is left,
neither on AppState nor in the code that uses it."""

from __future__ import annotations

import ast
from dataclasses import fields
from pathlib import Path

from shadelab.lab.state import SUB_STATES, AppState
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


# The flat names the pipelines merge still used (issue 21), by the sub-state field they were.
FORMER_FLAT_NAMES = {
    **{name: ("view", name) for name in (
        "compare", "diff_enabled", "msaa", "pipeline", "pipeline_view", "presenter",
        "radiosity_patches", "render_scale", "show_help", "show_normals", "show_wireframe",
        "viewport_size", "wipe", "wipe_pipeline", "wipe_position")},
    "job": ("offline", "runner"), "job_kind": ("offline", "kind"),
    "job_size": ("offline", "size"), "job_spp": ("offline", "spp"),
    "job_compare": ("offline", "comparison"), "job_raster": ("offline", "raster"),
    "job_kinds": ("offline", "kinds"), "job_version": ("offline", "version"),
    "job_scene": ("offline", "scene"), "job_size_px": ("offline", "size_px"),
    **{name: ("offline", name) for name in (
        "ray_tree", "ray_tree_pixel", "radiosity_soup", "show_radiosity", "overlay_version")},
    "lesson": ("walk", "lesson"),
}
ROOT = Path(__file__).resolve().parents[2]


def test_no_flat_name_remains():
    """A sub-state field is not an AppState attribute (unless AppState has a field of that
    name); each former flat name is gone and its field reads and writes on its sub-state."""
    import shadelab.lab.state as state_module

    assert not hasattr(state_module, "REMAINING_FLAT_NAMES")
    assert not hasattr(state_module, "_In")
    state = _state()
    own = {g.name for g in fields(AppState)}
    for cls in SUB_STATES.values():
        for f in fields(cls):
            if f.name not in SUB_STATES:
                assert not hasattr(state, f.name) or f.name in own
                assert not hasattr(AppState, f.name) or f.name in own
    for name, (part, field_name) in FORMER_FLAT_NAMES.items():
        assert field_name in {f.name for f in fields(SUB_STATES[part])}, name
        assert name not in own and not hasattr(AppState, name), name
        assert not hasattr(state, name), name
        sub = getattr(state, part)
        marker = object()
        setattr(sub, field_name, marker)
        assert getattr(sub, field_name) is marker
        assert not hasattr(state, name), name
    assert not hasattr(state, "probe_pixel") and not hasattr(state, "study_index")
    assert not hasattr(state, "focus_request") and not hasattr(state, "show_gizmos")


def _flat_uses(path: Path) -> list[str]:
    """``<...>state.<former flat name>`` in a source file (a dataclass instance would take a
    stray attribute silently, so a missed writer is found here)."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Attribute) and node.attr in FORMER_FLAT_NAMES:
            owner = node.value
            name = owner.id if isinstance(owner, ast.Name) else \
                owner.attr if isinstance(owner, ast.Attribute) else ""
            if name in ("state", "app_state"):
                found.append(f"{path.relative_to(ROOT)}:{node.lineno}: {name}.{node.attr}")
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Name) \
                and node.func.id in ("getattr", "setattr", "hasattr") and len(node.args) >= 2 \
                and isinstance(node.args[0], ast.Name) and node.args[0].id == "state" \
                and isinstance(node.args[1], ast.Constant) \
                and node.args[1].value in FORMER_FLAT_NAMES:
            found.append(f"{path.relative_to(ROOT)}:{node.lineno}: {node.func.id}(state, "
                         f"{node.args[1].value!r})")
    return found


def test_no_code_uses_a_flat_name():
    files = sorted((ROOT / "app").rglob("*.py")) + sorted((ROOT / "tests").rglob("*.py"))
    assert len(files) > 50
    uses = [use for path in files if path.name != Path(__file__).name
            for use in _flat_uses(path)]
    assert uses == []


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
