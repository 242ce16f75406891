"""The viewer's start-up: Python's cyclic garbage collector paused until the first frame.

Start-up makes hundreds of thousands of objects that live as long as the process (modules,
classes, numpy's and imgui-bundle's bindings, the scene): every 700 allocations start a
collection that walks the young ones and every tenth of those the older ones, about 130
collections before the first frame, 50-70 ms of the ~1 s to it on two cores, that find next
to nothing to free. ``shadelab view`` pauses the collector from its start and the viewer
resumes it once the first frame is on screen (or when the command ends without one). Only a
collector this module paused is resumed: one the caller turned off stays off."""

from __future__ import annotations

import gc

_paused = False


def pause_gc() -> None:
    """Turn the cyclic collector off until :func:`resume_gc` (a no-op when it is off)."""
    global _paused
    if gc.isenabled():
        gc.disable()
        _paused = True


def resume_gc() -> None:
    """Turn the collector back on if :func:`pause_gc` turned it off (else a no-op)."""
    global _paused
    if _paused:
        _paused = False
        gc.enable()


def gc_paused() -> bool:
    """True while :func:`pause_gc` holds the collector off."""
    return _paused
