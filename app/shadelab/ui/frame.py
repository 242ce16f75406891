"""Frame safety: an error inside a panel closes the ImGui scopes it opened and reaches the
status line, instead of aborting the process ("Missing EndChild()").

ImGui (1.91.5+) keeps an error-recovery snapshot of its stacks: we store one before a panel
draws and, when the panel raises, roll every stack (windows, children, tree nodes, tables,
IDs, groups, disabled blocks, style pushes) back to it, with ImGui's own assert disabled for
that roll-back so it does not raise in its turn.
"""

from __future__ import annotations

import os
import sys
import traceback
from typing import Callable

from imgui_bundle import imgui

from shadelab.errors import ShadeLabError


def error_message(where: str, exc: BaseException) -> str:
    """One line: the panel, then the reason (a ShadeLabError is already worded for users)."""
    if isinstance(exc, ShadeLabError):
        return f"{where}: {exc}"
    return f"{where}: {type(exc).__name__}: {exc}".splitlines()[0]


def guarded(draw: Callable[[], object], where: str, report: Callable[[str], None],
            default: object = False) -> object:
    """Run ``draw()``; on an exception close the scopes it left open, ``report`` one line and
    return ``default``."""
    internal = imgui.internal
    saved = internal.ErrorRecoveryState()
    internal.error_recovery_store_state(saved)
    try:
        return draw()
    except Exception as exc:  # every error a panel raises ends here, scopes closed
        io = imgui.get_io()
        assert_before = io.config_error_recovery_enable_assert
        tooltip_before = io.config_error_recovery_enable_tooltip
        io.config_error_recovery_enable_assert = False
        io.config_error_recovery_enable_tooltip = False
        try:
            internal.error_recovery_try_to_recover_state(saved)
        finally:
            io.config_error_recovery_enable_assert = assert_before
            io.config_error_recovery_enable_tooltip = tooltip_before
        message = error_message(where, exc)
        report(message)
        _tell(message, exc)
        return default


_told: list[str] = []   # the last message written to stderr (one line, not once per frame)


def _tell(message: str, exc: BaseException) -> None:
    """One line on stderr per new error, no traceback (the status line shows it too); the
    whole story with SHADELAB_DEBUG=1."""
    if os.environ.get("SHADELAB_DEBUG"):
        traceback.print_exception(exc)
        return
    if _told[-1:] != [message]:
        _told[:] = [message]
        print(f"shadelab: {message}", file=sys.stderr)
