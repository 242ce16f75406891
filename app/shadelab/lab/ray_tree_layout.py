"""The ray tree of one pixel as the lecture's slide draws it: a 2D node diagram (pure, no GL,
no GUI; :mod:`shadelab.ui.ray_tree_panel` draws it).

Each ray of a :class:`shadelab.raytrace.tree.RayNode` tree is a box: the surface it hit (the
object's name, or "background"; a shadow ray: its light, lit or blocked) and, for the rays
that add light, its contribution ``c`` to the pixel. The edge into each box carries a label:
the ray's kind, its own factor (kr for reflected, kt for refracted) and its weight ``w`` (the
product of the factors from the pixel down).

Layout: the leaves of the tree sit on a grid of slots (a shadow ray's narrower, wide enough
for ``SHADOW_TEXT``); a node spans the slots of its subtree's leaves (width from the subtree's leaf
count) and is centred over them, one row per
tree level. Every row is three bands: the wires from the parents, the edge labels, the node
boxes. Boxes of one band lie in disjoint slot ranges and bands do not share rows, so no two
boxes overlap (:func:`overlapping` checks it pairwise). Text wraps to its slot; when the slot
is too narrow for ``MIN_TEXT`` the whole diagram is laid out at that width and
scaled down to fit (``Diagram.scale``, also the font scale to draw with).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

#: Digits of the contributions shown: their sum matches the pixel within half a unit of the
#: last digit per node shown.
DIGITS = 3
#: What a leaf slot holds on one line at least (else the diagram is scaled down)
MIN_TEXT = ("reflected", "refracted", "background", "c=(0.000,")
#: What a shadow ray's (narrower) leaf slot holds on one line at least
SHADOW_TEXT = ("shadow", "L0 lit")


@dataclass(frozen=True)
class Box:
    x: float
    y: float
    w: float
    h: float

    def overlaps(self, other: Box) -> bool:
        return (self.x < other.x + other.w and other.x < self.x + self.w
                and self.y < other.y + other.h and other.y < self.y + self.h)

    def contains(self, px: float, py: float) -> bool:
        return self.x <= px <= self.x + self.w and self.y <= py <= self.y + self.h

    def scaled(self, s: float) -> Box:
        return Box(self.x * s, self.y * s, self.w * s, self.h * s)


@dataclass
class DiagramNode:
    """One ray's box and the label of the edge into it."""

    node: object                  # the RayNode
    parent: int                   # index into Diagram.nodes, -1 for the root
    level: int                    # depth in the tree (0: the primary ray)
    kind: str
    title: str                    # the surface hit ("background", "light 0: lit", ...)
    lines: list[str]              # the box's text, wrapped
    label_lines: list[str]        # the edge label's text, wrapped
    box: Box = None
    label: Box = None
    shown: np.ndarray | None = None   # the contribution as printed (rounded), or None


@dataclass
class Diagram:
    nodes: list[DiagramNode]
    width: float
    height: float
    scale: float = 1.0            # < 1: laid out wider and scaled down (font scale too)
    line_h: float = 14.0          # text line height after scaling
    pixel: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def boxes(self) -> list[Box]:
        """Every node and label box."""
        return [b for n in self.nodes for b in (n.box, n.label)]

    def wires(self) -> list[tuple[tuple[float, float], tuple[float, float]]]:
        """(parent's bottom centre, child's label top centre) of every edge."""
        out = []
        for n in self.nodes:
            if n.parent >= 0:
                p = self.nodes[n.parent].box
                out.append(((p.x + p.w / 2, p.y + p.h), (n.label.x + n.label.w / 2, n.label.y)))
        return out

    def node_at(self, px: float, py: float) -> DiagramNode | None:
        for n in self.nodes:
            if n.box.contains(px, py) or n.label.contains(px, py):
                return n
        return None


def overlapping(boxes: Sequence[Box]) -> list[tuple[int, int]]:
    """Index pairs of boxes that overlap (pairwise check)."""
    return [(i, j) for i in range(len(boxes)) for j in range(i + 1, len(boxes))
            if boxes[i].overlaps(boxes[j])]


def fmt(v: np.ndarray, digits: int = DIGITS) -> str:
    """One number when the channels agree at this precision, else (r, g, b)."""
    parts = [f"{float(c):.{digits}f}" for c in np.asarray(v, float)]
    return parts[0] if len(set(parts)) == 1 else "(" + ", ".join(parts) + ")"


def shown_value(v: np.ndarray, digits: int = DIGITS) -> np.ndarray:
    """The RGB a :func:`fmt` text stands for."""
    return np.array([float(f"{float(c):.{digits}f}") for c in np.asarray(v, float)])


def _factor(node, parent) -> np.ndarray:
    pw = np.asarray(parent.weight, float)
    return np.divide(np.asarray(node.weight, float), pw, out=np.zeros(3), where=pw > 0)


def node_texts(node, parent, names: Sequence[str], pixel: tuple | None = None):
    """(title, box lines, label lines, shown contribution or None) of one ray."""
    def name(i):
        return names[i] if 0 <= i < len(names) else "background"

    if node.kind == "shadow":
        if node.shadow >= 1.0:
            title = f"L{node.light} lit"
        elif node.object >= 0:
            title = f"L{node.light} blocked by {name(node.object)}"
        else:
            title = f"L{node.light} S={node.shadow:.2f}"
        label = ["shadow"]
        return title, [title], label, None
    title = name(node.object) if node.end is not None else "background"
    shown = shown_value(node.contribution)
    lines = [title, f"c={fmt(node.contribution)}"]
    if node.kind == "primary":
        where = f" {tuple(pixel)}" if pixel is not None else ""
        label = [f"primary: pixel{where}"]
    else:
        k = "kr" if node.kind == "reflected" else "kt"
        label = [node.kind, f"{k}={fmt(_factor(node, parent), 2)}",
                 f"w={fmt(node.weight, 2)}"]
    return title, lines, label, shown


def _wrap(lines: Sequence[str], width: float, measure: Callable[[str], float]) -> list[str]:
    """Words onto lines no wider than ``width``; a word too long is cut."""
    out = []
    for line in lines:
        cur = ""
        for word in line.split(" "):
            trial = word if not cur else cur + " " + word
            if measure(trial) <= width:
                cur = trial
                continue
            if cur:
                out.append(cur)
            cur = ""
            for ch in word:
                if cur and measure(cur + ch) > width:
                    out.append(cur)
                    cur = ""
                cur += ch
        out.append(cur)
    return out


def layout(root, names: Sequence[str], width: float, *, char_w: float = 7.0,
           line_h: float = 14.0, measure: Callable[[str], float] | None = None,
           min_text: Sequence[str] = MIN_TEXT, pad: float = 4.0, wire_h: float | None = None,
           pixel: tuple | None = None) -> Diagram:
    """The diagram of the tree ``root`` in ``width`` pixels.

    ``names``: object names by index (``scene.objects``); ``measure(text)`` a text's width in
    pixels at scale 1 (default ``len(text) * char_w``), ``line_h`` a line's height. Text wraps
    to its leaf slot; if a slot would be narrower than the widest of ``min_text`` the diagram is
    laid out at that slot width and scaled by ``width / natural width``.
    """
    measure = measure or (lambda s: len(s) * char_w)
    wire_h = 1.2 * line_h if wire_h is None else wire_h
    least = max(measure(t) for t in min_text) + 4 * pad       # a leaf slot's least width
    shadow_slot = min(1.0, (max(measure(t) for t in SHADOW_TEXT) + 4 * pad) / least)
    nodes: list[DiagramNode] = []
    units: dict[int, float] = {}
    children: dict[int, list[int]] = {}

    def visit(node, parent_index, level):
        parent = nodes[parent_index].node if parent_index >= 0 else None
        title, lines, label, shown = node_texts(node, parent, names, pixel)
        index = len(nodes)
        nodes.append(DiagramNode(node, parent_index, level, node.kind, title, lines, label,
                                 shown=shown))
        children[index] = []
        below = 0.0
        for child in node.children:
            children[index].append(len(nodes))
            below += visit(child, index, level + 1)
        own = shadow_slot if node.kind == "shadow" else 1.0
        units[index] = max(below, own)
        return units[index]

    total_units = visit(root, -1, 0)
    slot = max(width / total_units, least)
    natural = slot * total_units
    scale = min(1.0, width / natural)

    # horizontal intervals: children share their parent's, by their subtrees' leaf widths,
    # centred when they need less
    start = {0: 0.0}
    for i in range(len(nodes)):
        at = start[i] + (units[i] - sum(units[j] for j in children[i])) / 2
        for j in children[i]:
            start[j] = at
            at += units[j]
    for i, n in enumerate(nodes):
        span = units[i] * slot - 2 * pad
        n.lines = _wrap(n.lines, span - 2 * pad, measure)
        n.label_lines = _wrap(n.label_lines, span - 2 * pad, measure)

    levels = max(n.level for n in nodes) + 1
    y = 0.0
    for level in range(levels):
        row = [i for i, n in enumerate(nodes) if n.level == level]
        if level:
            y += wire_h
        label_h = max(len(nodes[i].label_lines) for i in row) * line_h + pad
        node_h = max(len(nodes[i].lines) for i in row) * line_h + 2 * pad
        for i in row:
            n = nodes[i]
            x0, span = start[i] * slot + pad, units[i] * slot - 2 * pad
            text_w = max(measure(s) for s in n.lines) + 2 * pad
            box_w = min(span, max(text_w, measure("M") * 4))
            lab_w = min(span, max(measure(s) for s in n.label_lines) + 2 * pad)
            n.label = Box(x0 + (span - lab_w) / 2, y, lab_w, label_h - pad)
            n.box = Box(x0 + (span - box_w) / 2, y + label_h, box_w, node_h)
        y += label_h + node_h
    if scale < 1.0:
        for n in nodes:
            n.box, n.label = n.box.scaled(scale), n.label.scaled(scale)
    pixel_value = np.asarray(root.total(), float)
    return Diagram(nodes, natural * scale, y * scale, scale, line_h * scale, pixel_value)
