"""Native file dialogs (imgui-bundle's portable-file-dialogs), drag-and-drop of files onto the
window, and the "discard unsaved changes?" question.

The native dialogs run asynchronously: :func:`ask` starts one and :func:`poll` (once a frame)
takes its answer when it is ready, so the viewer keeps drawing meanwhile. Tests replace
:data:`BACKEND` (the ``pfd`` module) by a stub with the same ``open_file`` / ``save_file``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from imgui_bundle import imgui
from imgui_bundle import portable_file_dialogs as pfd

from shadelab.geometry.mesh import MESH_SUFFIXES
from shadelab.lab.state import AppState

BACKEND = pfd
PRESET_FILTER = ["Presets (.toml)", "*.toml"]
MESH_FILTER = ["Meshes", " ".join(f"*{s}" for s in MESH_SUFFIXES)]
ALL_FILTER = ["All files", "*"]
DISCARD_POPUP = "Discard unsaved changes?"


@dataclass
class Pending:
    purpose: str       # "open" | "save" | "mesh"
    dialog: object     # pfd.open_file / pfd.save_file (ready(), result())


_pending: Pending | None = None
_dropped: list[str] = []


def ask(state: AppState, purpose: str) -> None:
    """Start a native dialog: "open" (a preset or mesh), "save" (Save as) or "mesh"."""
    global _pending
    if _pending is not None:
        return  # one at a time
    folder = str(Path(state.preset_path).parent) if state.preset_path else "."
    try:
        if purpose == "save":
            name = state.preset_path or f"{state.scene.name or 'scene'}.toml"
            dialog = BACKEND.save_file("Save the preset as", name, PRESET_FILTER + ALL_FILTER)
        elif purpose == "mesh":
            dialog = BACKEND.open_file("Add a mesh", folder, MESH_FILTER + ALL_FILTER)
        else:
            dialog = BACKEND.open_file("Open a preset or mesh", folder,
                                       PRESET_FILTER + MESH_FILTER + ALL_FILTER)
    except Exception as exc:  # no dialog helper on this desktop (zenity, kdialog)
        state.error = f"file dialog: {exc}; type the path in the File field instead"
        return
    _pending = Pending(purpose, dialog)


def poll(state: AppState) -> None:
    """Take a finished dialog's answer (an empty answer is a cancel) and act on it."""
    global _pending
    if _pending is None or not _pending.dialog.ready(0):
        return
    purpose, result = _pending.purpose, _pending.dialog.result()
    _pending = None
    paths = [result] if isinstance(result, str) else list(result or [])
    paths = [p for p in paths if p]
    if not paths:
        state.status = f"{purpose}: cancelled"
        return
    path = paths[0]
    state.open_path = path
    if purpose == "save":
        state.save_as(path)
    elif purpose == "mesh":
        state.add_mesh(path)
    else:
        state.request_open(path)


def busy() -> bool:
    return _pending is not None


# ---------------------------------------------------------------- drag and drop


def on_drop(paths) -> None:
    """GLFW's drop callback: queue the files (handled at the frame's end)."""
    _dropped.extend(str(p) for p in paths)


def install_drop_callback() -> bool:
    """Route files dropped on the window to :func:`on_drop` (False without a GLFW window)."""
    try:
        import glfw
        from imgui_bundle import glfw_utils

        window = glfw_utils.glfw_window_hello_imgui()
        glfw.set_drop_callback(window, lambda _window, paths: on_drop(paths))
        return True
    except Exception:  # no GLFW backend
        return False


def take_dropped(state: AppState) -> None:
    """Open the dropped files: presets replace the scene (asking first), meshes are added."""
    while _dropped:
        path = _dropped.pop(0)
        if Path(path).suffix.lower() in MESH_SUFFIXES:
            state.add_mesh(path)
        else:
            state.request_open(path)
            if state.pending_open:
                _dropped.clear()  # one question at a time
                return


# ---------------------------------------------------------------- unsaved edits


def draw_discard_question(state: AppState) -> None:
    """The modal that answers ``state.pending_open`` (opening a file over unsaved edits)."""
    if state.pending_open and not imgui.is_popup_open(DISCARD_POPUP):
        imgui.open_popup(DISCARD_POPUP)
    if not imgui.begin_popup_modal(DISCARD_POPUP, None,
                                   imgui.WindowFlags_.always_auto_resize)[0]:
        return
    imgui.text(f"'{state.title().removeprefix('ShadeLab - ').rstrip(' *')}' has unsaved edits.")
    imgui.text(f"Open '{state.pending_open}' instead? (Ctrl+Z brings the edits back.)")
    if imgui.button("Open (discard)"):
        path, state.pending_open = state.pending_open, ""
        state.open_file(path)
        imgui.close_current_popup()
    imgui.same_line()
    if imgui.button("Save first") and (state.preset_path or state.open_path):
        path, state.pending_open = state.pending_open, ""
        if state.save_as(state.preset_path or state.open_path):
            state.open_file(path)
        imgui.close_current_popup()
    imgui.same_line()
    if imgui.button("Cancel") or not state.pending_open:
        state.pending_open = ""
        imgui.close_current_popup()
    imgui.end_popup()
