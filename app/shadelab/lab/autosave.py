"""The session autosave: the scene written at most once per :data:`AUTOSAVE_INTERVAL` while it
has changed, never mid-edit (a slider still held), and once more at exit."""

from __future__ import annotations

import time
from dataclasses import dataclass

from shadelab.lab.state import AUTOSAVE_INTERVAL, AppState, save_session


@dataclass
class Autosave:
    last: float = 0.0                 # perf_counter() of the last attempt

    def __call__(self, state: AppState, force: bool = False) -> None:
        now = time.perf_counter()
        if not state.autosave_due or state.edit_pending and not force:
            return
        if not force and now - self.last < AUTOSAVE_INTERVAL:
            return
        try:
            save_session(state.scene, state.source)
            state.autosave_due = False
        except Exception as exc:  # a full disk must not take the session down
            state.error = f"autosave failed: {exc}"
        self.last = now
