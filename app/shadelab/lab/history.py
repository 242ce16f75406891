"""Undo/redo of the viewer: :class:`History` keeps one Scene snapshot per finished edit.

Pure module (no GL, no GUI); :class:`shadelab.lab.state.AppState` owns one.
"""

from __future__ import annotations

from shadelab.scene.model import Scene
from shadelab.scene.preset import clone_scene, scene_to_dict

HISTORY_LIMIT = 200          # undo snapshots kept


def _without_camera(scene: Scene) -> dict:
    d = scene_to_dict(scene)
    d.pop("camera", None)
    return d


class History:
    """Undo/redo over Scene snapshots (one per finished edit, e.g. a slider release).

    Camera moves are not on the stack (an orbit is no edit to undo); opening a preset is
    (``file`` is what the title and "Save" need to go back to the file shown before)."""

    def __init__(self, scene: Scene, file: dict | None = None):
        self.snapshots = [clone_scene(scene)]
        self.files = [file]
        self.index = 0

    def push(self, scene: Scene, file: dict | None = None) -> None:
        if file is None and _without_camera(scene) == _without_camera(self.snapshots[self.index]):
            return  # nothing changed (a slider clicked but not moved, or the camera only)
        del self.snapshots[self.index + 1:]
        del self.files[self.index + 1:]
        self.snapshots.append(clone_scene(scene))
        self.files.append(file if file is not None else self.files[self.index])
        if len(self.snapshots) > HISTORY_LIMIT:
            self.snapshots.pop(0)
            self.files.pop(0)
        self.index = len(self.snapshots) - 1

    def file(self) -> dict | None:
        return self.files[self.index]

    def can_undo(self) -> bool:
        return self.index > 0

    def can_redo(self) -> bool:
        return self.index < len(self.snapshots) - 1

    def undo(self) -> Scene | None:
        if not self.can_undo():
            return None
        self.index -= 1
        return clone_scene(self.snapshots[self.index])

    def redo(self) -> Scene | None:
        if not self.can_redo():
            return None
        self.index += 1
        return clone_scene(self.snapshots[self.index])
