"""ui/ holds one module per dock window: every window of the docking table (ui/app.py's
``_docking``) draws through a function of its own module, no two windows share one, and
ui/panels.py keeps only the shared widgets (no ``draw_*_panel``)."""

from __future__ import annotations

import ast
from pathlib import Path

import shadelab

UI = Path(shadelab.__file__).parent / "ui"


def _windows() -> dict[str, str]:
    """Window label -> the module its draw function comes from (read from the source)."""
    tree = ast.parse((UI / "app.py").read_text(encoding="utf-8"))
    imported = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("shadelab.ui."):
            for alias in node.names:
                imported[alias.asname or alias.name] = node.module.rsplit(".", 1)[1]
    docking = next(n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == "_docking")
    out = {}
    for node in ast.walk(docking):
        if isinstance(node, ast.Call) and getattr(node.func, "id", "") == "window":
            label = node.args[0].value
            gui = node.args[2]
            if isinstance(gui, ast.Call) and getattr(gui.func, "id", "") == "p":
                target = gui.args[0]
                if isinstance(target, ast.Attribute):
                    out[label] = target.value.id
                else:
                    out[label] = imported.get(target.id, "app")
            else:
                out[label] = "app"  # the viewport itself
    return out


def test_each_dock_window_has_its_own_module():
    windows = _windows()
    assert {"Scene", "Lights", "Materials", "Objects", "Equation & probe"} <= set(windows)
    modules = [m for label, m in windows.items() if label != "Viewport"]
    shared = {m for m in modules if modules.count(m) > 1 and m != "studies_panel"}
    assert not shared, windows   # (Studies and Failure gallery share the studies module)
    assert "panels" not in modules and "app" not in modules, windows
    for module in set(modules):
        assert (UI / f"{module}.py").exists(), module


def test_panels_keeps_only_the_shared_widgets():
    tree = ast.parse((UI / "panels.py").read_text(encoding="utf-8"))
    drawn = [n.name for n in tree.body if isinstance(n, ast.FunctionDef)
             and n.name.startswith("draw_")]
    assert drawn == []
