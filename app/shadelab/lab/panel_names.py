"""The viewer's dock windows by name (their labels in shadelab.ui.app._docking), for what
names them before any window is open: ``--focus`` and a lesson step's ``focus`` key. No GUI."""

from __future__ import annotations

PANEL_LABELS = ("Scene", "Lights", "Materials", "Objects", "Viewport", "Equation & probe",
                "Studies", "Failure gallery", "Offline render", "Algorithms", "Hemicube & F",
                "Exercise", "Ray tree")


def unknown_panel(focus: str) -> str | None:
    """The first comma-separated word of ``focus`` that names no panel (a label prefix or a
    word of a label, as shadelab.ui.layout.focus_windows matches), else None."""
    for word in (w.strip().lower() for w in focus.split(",")):
        if not word or not any(label.lower().startswith(word) or word in label.lower()
                               for label in PANEL_LABELS):
            return word
    return None
