"""A lesson step's controls on stage (issue 22): the 2-4 parameters a slide is about, named by
the dotted paths ``--set`` takes (``materials.plastic.n``, ``render.specular``,
``lights.0.c2``), resolved against the step's scene.

Pure (no GUI): :func:`resolve` finds the owner object and the field of a path and says what
widget the field wants (its spec's kind); :func:`check_controls` is what a lesson load runs
(one line naming the path and what was expected); the presenter strip
(:func:`shadelab.ui.presenter.draw_controls_strip`) draws them and writes through
:func:`set_value` (a validated assignment, then ``state.mark_edited()`` as the panels do).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from shadelab.errors import ShadeLabError

# Field kinds (shadelab.scene.model.spec) a control can show, and the widget each gets
WIDGETS = {"float": "slider", "int": "slider", "bool": "checkbox", "str": "combo",
           "rgb": "color", "rgb01": "color"}
MAX_CONTROLS = 4


@dataclass(frozen=True)
class Control:
    """One control: where it lives and how it is drawn."""

    path: str          # the dotted path, as written in the lesson
    owner: Any         # the scene object holding the field (a Material, a Light, ...)
    field: str         # the field's name on ``owner``
    kind: str          # the field spec's kind: float | int | bool | str | rgb | rgb01
    args: tuple        # the spec's arguments (range, choices)
    label: str         # what the strip shows

    @property
    def widget(self) -> str:
        return WIDGETS[self.kind]

    @property
    def cls(self) -> type:
        return type(self.owner)

    def value(self) -> Any:
        return getattr(self.owner, self.field)


def _spec_of(owner: Any, name: str) -> tuple | None:
    if not dataclasses.is_dataclass(owner):
        return None
    for f in dataclasses.fields(owner):
        if f.name == name and "spec" in f.metadata:
            return f.metadata["spec"]
    return None


def control_label(path: str) -> str:
    """``materials.plastic.n`` -> ``plastic n``; ``lights.0.c2`` -> ``light 0 c2``;
    ``render.specular`` -> ``specular``; ``render.show_volumes`` -> ``show volumes``."""
    parts = path.split(".")
    field = parts[-1].replace("_", " ")
    if len(parts) == 3 and parts[0] == "materials":
        return f"{parts[1]} {field}"
    if len(parts) == 3 and parts[0] == "lights":
        return f"light {parts[1]} {field}"
    return field


def resolve(scene, path: str) -> Control:
    """The :class:`Control` of ``path`` in ``scene``; ShadeLabError (one line) when the path
    names no field or a field no control can show."""
    if not isinstance(path, str) or not path.strip():
        raise ShadeLabError(f"control {path!r}: expected a dotted path such as "
                            "'materials.plastic.n'")
    parts = path.strip().split(".")
    node: Any = scene
    for depth, part in enumerate(parts[:-1]):
        here = ".".join(parts[:depth + 1])
        if isinstance(node, list):
            if not (part.isascii() and part.isdigit()) or int(part) >= len(node):
                raise ShadeLabError(f"control '{path}': '{here}': expected an index below "
                                    f"{len(node)}")
            node = node[int(part)]
        elif isinstance(node, dict):
            if part not in node:
                raise ShadeLabError(f"control '{path}': no '{part}' (expected one of "
                                    f"{', '.join(node) or '(none)'})")
            node = node[part]
        elif dataclasses.is_dataclass(node) and hasattr(node, part) \
                and not part.startswith("_"):
            node = getattr(node, part)
        else:
            raise ShadeLabError(f"control '{path}': no '{part}' in '{here}'")
    name = parts[-1]
    spec = _spec_of(node, name)
    if spec is None:
        known = [f.name for f in dataclasses.fields(node) if "spec" in f.metadata] \
            if dataclasses.is_dataclass(node) else []
        raise ShadeLabError(f"control '{path}': no field '{name}'"
                            + (f" (expected one of {', '.join(known)})" if known else ""))
    kind, *args = spec
    if kind not in WIDGETS or (kind == "str" and not args[0]):
        raise ShadeLabError(f"control '{path}': a '{kind}' field has no control (expected a "
                            "number, a switch, a choice or a color)")
    label = control_label(path.strip())
    if parts[0] == "lights" and len(parts) == 3 and getattr(node, "name", ""):
        label = f"{node.name} {name.replace('_', ' ')}"   # its own name: "red Ip", "key c2"
    return Control(path.strip(), node, name, kind, tuple(args), label)


def check_controls(scene, paths) -> list[Control]:
    """Every path of a step's ``controls`` resolved in its scene (the lesson load's check)."""
    if not isinstance(paths, list) or not all(isinstance(p, str) for p in paths):
        raise ShadeLabError("'controls' must be a list of dotted paths")
    if len(paths) > MAX_CONTROLS:
        raise ShadeLabError(f"'controls': expected at most {MAX_CONTROLS} paths, got "
                            f"{len(paths)}")
    return [resolve(scene, p) for p in paths]


def set_value(control: Control, value: Any) -> bool:
    """Assign ``value`` (validated by the scene model); True when it changed the field."""
    before = control.value()
    setattr(control.owner, control.field, value)
    return control.value() != before
