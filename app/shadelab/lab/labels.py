"""Words in the scene: what each object of a figure shows (its kd, its ka, its ks and n; a
transparent pane's model and kt), object and material names on demand, and where on the
viewport they go. Pure numpy (no GL, no GUI): :mod:`shadelab.ui.scene_labels` draws them.

A *figure* is a row or grid of objects of one shape whose materials differ only in the
lecture's coefficients (ka, kd, ks, n): kd-grid, ka-grid, ks-n-grid. Each of its objects is
labelled with the coefficients that vary, below the object on screen.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from shadelab.geometry.mesh import MeshData
from shadelab.scene.camera import clip_from_world
from shadelab.scene.model import Material, Scene

COEFFICIENTS = ("ka", "kd", "ks", "n")   # what a figure's objects may differ in
FIGURE_MIN = 3                           # objects of one shape that make a figure
LABEL_GAP = 6.0                          # pixels between an object's bottom and its label


@dataclass
class Label:
    """A text at ``anchor`` (viewport pixels, x right, y down): centred on x, its top at y."""

    text: str
    anchor: tuple[float, float]
    object_index: int


def _fmt(value: float) -> str:
    return f"{value:.3g}"


def _same_but_coefficients(a: Material, b: Material) -> bool:
    from dataclasses import fields

    return all(getattr(a, f.name) == getattr(b, f.name) for f in fields(Material)
               if f.name not in COEFFICIENTS)


def figure_values(scene: Scene) -> dict[int, str]:
    """Object index -> the text written under it: the coefficients that vary across its
    figure, one a line ("kd = 0.25"; "ks = 0.4" over "n = 30"), and for a transparent object
    its name, model and kt. Objects in no figure and not transparent get none."""
    out: dict[int, str] = {}
    groups: dict[str, list[int]] = {}
    for i, obj in enumerate(scene.objects):
        if obj.material in scene.materials:
            groups.setdefault(obj.shape, []).append(i)
    for members in groups.values():
        if len(members) < FIGURE_MIN:
            continue
        materials = [scene.materials[scene.objects[i].material] for i in members]
        if not all(_same_but_coefficients(materials[0], m) for m in materials[1:]):
            continue
        varying = [c for c in COEFFICIENTS
                   if len({getattr(m, c) for m in materials}) > 1]
        if not varying:
            continue
        for i, m in zip(members, materials, strict=True):
            out[i] = "\n".join(f"{c} = {_fmt(getattr(m, c))}" for c in varying)
    for i, obj in enumerate(scene.objects):
        m = scene.materials.get(obj.material)
        if m is not None and m.kt > 0.0 and i not in out:
            name = obj.name or f"object {i}"
            model = "" if m.transparency in name else f"{m.transparency}, "
            out[i] = f"{name}\n{model}kt = {_fmt(m.kt)}"
    return out


def object_names(scene: Scene) -> dict[int, str]:
    """Object index -> "name (material)" for the View menu's names toggle."""
    return {i: f"{obj.name or f'object {i}'} ({obj.material})"
            for i, obj in enumerate(scene.objects)}


def project(scene: Scene, aspect: float, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(N, 2) normalized device coordinates of world ``points`` (N, 3) through the scene's
    camera at ``aspect`` = width / height, and (N,) True where the point is before the eye."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    cam = scene.camera
    span = float(np.linalg.norm(np.subtract(cam.target, cam.eye))) or 1.0
    clip = clip_from_world(cam, aspect, far=1e3 * span) @ np.c_[points, np.ones(len(points))].T
    w = clip[3]
    front = w > 1e-9
    ndc = (clip[:2] / np.where(front, w, 1.0)).T
    return ndc, front


def to_pixels(scene: Scene, size: tuple[int, int], point) -> tuple[float, float] | None:
    """Viewport pixel (x right, y down) of a world point; None behind the eye."""
    ndc, front = project(scene, size[0] / max(size[1], 1), np.asarray(point)[None])
    if not front[0]:
        return None
    return float((ndc[0, 0] * 0.5 + 0.5) * size[0]), float((0.5 - ndc[0, 1] * 0.5) * size[1])


def screen_box(scene: Scene, mesh: MeshData, size: tuple[int, int]) -> tuple | None:
    """(x0, y0, x1, y1) viewport pixels of the mesh's vertices on screen, or None when one is
    behind the eye."""
    if len(mesh.vertices) == 0:
        return None
    ndc, front = project(scene, size[0] / max(size[1], 1), mesh.vertices)
    if not front.all():
        return None
    x = (ndc[:, 0] * 0.5 + 0.5) * size[0]
    y = (0.5 - ndc[:, 1] * 0.5) * size[1]
    return float(x.min()), float(y.min()), float(x.max()), float(y.max())


def inside_top(scene: Scene) -> set[int]:
    """Objects whose label goes inside the top of their screen box, not under it: flat
    transparent panes (a label under a pane would cover what is seen through it)."""
    return {i for i, obj in enumerate(scene.objects) if obj.shape in ("quad", "plane")
            and obj.material in scene.materials and scene.materials[obj.material].kt > 0.0}


def place_labels(scene: Scene, meshes: list[MeshData], size: tuple[int, int],
                 texts: dict[int, str], measure) -> list[Label]:
    """A :class:`Label` under each object ``texts`` names (centred below its screen box; a
    pane's inside its top edge, :func:`inside_top`), kept inside the viewport; objects off
    screen or behind the eye get none. ``measure(text) -> (width, height)`` in pixels: a
    label that would cover one placed before it moves to the nearest free place above or
    below."""
    inside = inside_top(scene)
    by_index = {m.index: m for m in meshes}
    out, boxes = [], []
    for i, text in texts.items():
        mesh = by_index.get(i)
        box = None if mesh is None else screen_box(scene, mesh, size)
        if box is None or box[2] < 0 or box[0] > size[0] or box[3] < 0 or box[1] > size[1]:
            continue
        w, h = measure(text)
        x = min(max(0.5 * (box[0] + box[2]), 0.5 * w), size[0] - 0.5 * w)
        want = box[1] + LABEL_GAP if i in inside else box[3] + LABEL_GAP
        want = max(min(want, size[1] - h), 0.0)
        # the free place nearest the wanted one: there, or just below or above a label
        candidates = [want] + [b[3] + 1.0 for b in boxes] + [b[1] - 1.0 - h for b in boxes]
        free = [c for c in sorted(candidates, key=lambda c: (abs(c - want), c))
                if 0.0 <= c <= size[1] - h
                and not any(_overlap(b, (x - 0.5 * w, c, x + 0.5 * w, c + h)) for b in boxes)]
        y = free[0] if free else want
        boxes.append((x - 0.5 * w, y, x + 0.5 * w, y + h))
        out.append(Label(text, (x, y), i))
    return out


def label_box(label: Label, measure) -> tuple[float, float, float, float]:
    """(x0, y0, x1, y1) of a placed label's text."""
    w, h = measure(label.text)
    return label.anchor[0] - 0.5 * w, label.anchor[1], label.anchor[0] + 0.5 * w, \
        label.anchor[1] + h


def _overlap(a, b) -> bool:
    """Two (x0, y0, x1, y1) rectangles share some area."""
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def frame_overflow(scene: Scene, meshes: list[MeshData], aspect: float) -> dict[int, float]:
    """Object index -> how far its vertices reach in normalized device coordinates (the
    largest |x| or |y|): above 1 it leaves the frame at that aspect; inf when behind the eye."""
    out = {}
    for mesh in meshes:
        ndc, front = project(scene, aspect, mesh.vertices)
        out[mesh.index] = float(np.abs(ndc).max()) if front.all() else float("inf")
    return out
