"""ViewportHost (shadelab.ui.viewport_host): the Viewer implements every member of the protocol,
and the layouts that take a viewer type it with the protocol and call nothing private of it."""

from __future__ import annotations

import ast
import inspect
import typing
from pathlib import Path

import shadelab

UI = Path(shadelab.__file__).parent / "ui"
TYPED = ("compare_view.py", "presenter.py", "pipeline_viewport.py")


def _members(proto) -> set[str]:
    return {n for n, v in vars(proto).items()
            if not n.startswith("_") and (callable(v) or isinstance(v, property))}


def test_the_viewer_implements_the_protocol():
    from shadelab.ui.app import Viewer
    from shadelab.ui.viewport_host import ViewportHost

    members = _members(ViewportHost)
    assert {"state", "viewport", "image_with_input", "unchanged", "samples"} <= members
    fields = set(Viewer.__dataclass_fields__)
    assert not hasattr(Viewer, "_image_with_input")  # the old name is gone (issue 21)
    for name in members:
        assert name in fields or callable(getattr(Viewer, name, None)), name
        if callable(getattr(Viewer, name, None)):
            want = list(inspect.signature(getattr(ViewportHost, name)).parameters)
            got = list(inspect.signature(getattr(Viewer, name)).parameters)
            assert got == want, name


def test_the_layouts_take_a_viewport_host():
    from shadelab.ui import compare_view, pipeline_viewport, presenter
    from shadelab.ui.viewport_host import ViewportHost

    for fn in (compare_view.draw_compare, presenter.draw_presenter_viewport, presenter.end_frame,
               pipeline_viewport.draw, pipeline_viewport._blank, pipeline_viewport._texture,
               pipeline_viewport._screenshot_pipeline):
        hints = typing.get_type_hints(fn)
        assert hints["viewer"] is ViewportHost, fn.__name__
    for name in TYPED:  # every function of a layout that takes a viewer types it
        tree = ast.parse((UI / name).read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef):
                for arg in node.args.args:
                    if arg.arg == "viewer":
                        assert arg.annotation is not None, f"{name}:{node.name}"
                        assert ast.unparse(arg.annotation) == "ViewportHost", f"{name}:{node.name}"


def test_no_private_viewer_member_is_used_outside_its_class():
    bad = []
    for path in sorted(UI.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if (isinstance(node, ast.Attribute) and node.attr.startswith("_")
                    and not node.attr.startswith("__")
                    and isinstance(node.value, ast.Name) and node.value.id in {"viewer", "host"}):
                bad.append(f"{path.name}:{node.lineno} viewer.{node.attr}")
    assert not bad, bad
