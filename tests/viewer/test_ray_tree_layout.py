"""The ray tree's 2D diagram (shadelab.lab.ray_tree_layout): one box per ray with its kind and
weight, contributions that add up to the pixel, no overlapping boxes, and a given width kept.
The picked pixels lie on the glass sphere of the shipped scenes (trees of depth >= 2)."""

from __future__ import annotations

import re

import numpy as np
import pytest

from shadelab.lab.ray_tree_layout import DIGITS, Box, layout, overlapping
from shadelab.raytrace.tree import trace_pixel_tree
from shadelab.scene.preset import load_preset

SIZE = (64, 48)
#: (preset, pixel of SIZE on the glass sphere, least tree depth there)
PICKS = [("whitted", (48, 28), 3), ("cornell-spheres", (32, 32), 2)]
#: 1024x768 presenter: the panel's width and a presenter font (1.5 x ProggyClean's 7x13)
PRESENTER = {"width": 480.0, "char_w": 10.5, "line_h": 20.0}

_trees: dict = {}


def _tree(preset: str, pixel):
    if preset not in _trees:
        scene = load_preset(preset)
        _trees[preset] = (scene, trace_pixel_tree(scene, SIZE, *pixel))
    return _trees[preset]


def _unwrapped(lines):
    """A box's text with the wrapping undone (spaces dropped: numbers may be cut anywhere)."""
    return "".join(lines).replace(" ", "")


def _names(scene):
    return [o.name or o.shape for o in scene.objects]


@pytest.mark.parametrize("preset,pixel,depth", PICKS)
def test_nodes_are_the_trees(preset, pixel, depth):
    scene, root = _tree(preset, pixel)
    rays = [node for _, node in root.flatten()]
    assert max(d for d, _ in root.flatten()) >= depth
    assert scene.objects[root.object].name in ("mirror_sphere", "glass_sphere")
    diagram = layout(root, _names(scene), 480.0, pixel=pixel)
    assert [n.node for n in diagram.nodes] == rays        # one box per ray, same order
    assert [n.kind for n in diagram.nodes] == [r.kind for r in rays]
    for n in diagram.nodes:
        if n.parent >= 0:
            assert n.node in diagram.nodes[n.parent].node.children
        if n.kind in ("reflected", "refracted"):
            # the label's w is the node's weight, its kr / kt the factor from the parent
            text = _unwrapped(n.label_lines)
            assert n.kind in text and ("kr=" in text if n.kind == "reflected" else "kt=" in text)
            w = re.search(r"w=\(?([0-9.,]+)\)?", text).group(1)
            shown = np.array([float(v) for v in w.split(",")])
            assert np.allclose(shown, np.round(n.node.weight, 2), atol=0.006)
        if n.node.end is None and n.kind != "shadow":
            assert n.title == "background"
    kinds = {n.kind for n in diagram.nodes}
    assert "shadow" in kinds and kinds & {"reflected", "refracted"}


@pytest.mark.parametrize("preset,pixel,depth", PICKS)
def test_contributions_shown_sum_to_the_pixel(preset, pixel, depth):
    """Each contribution is printed to DIGITS decimals: the printed ones (read back from the
    box text) add up to the tree's root radiance (RayNode.total) within half a unit of the
    last digit per printed contribution."""
    scene, root = _tree(preset, pixel)
    diagram = layout(root, _names(scene), 480.0)
    total, count = np.zeros(3), 0
    for n in diagram.nodes:
        text = _unwrapped(n.lines)
        m = re.search(r"c=\(?([0-9.,]+?)\)?$", text)
        if n.kind == "shadow":
            assert m is None and not np.any(n.node.contribution)
            continue
        values = [float(v) for v in m.group(1).split(",")]
        total += np.array(values * 3 if len(values) == 1 else values)
        count += 1
    tolerance = count * 0.5 * 10.0 ** -DIGITS + 1e-9
    assert np.allclose(total, root.total(), atol=tolerance), (total, root.total(), tolerance)
    assert np.allclose(diagram.pixel, root.total())
    assert np.any(root.total() > 0)


@pytest.mark.parametrize("preset,pixel,depth", PICKS)
@pytest.mark.parametrize("width", [480.0, 900.0, 200.0])
def test_no_boxes_overlap_and_the_width_is_kept(preset, pixel, depth, width):
    scene, root = _tree(preset, pixel)
    diagram = layout(root, _names(scene), width, char_w=PRESENTER["char_w"],
                     line_h=PRESENTER["line_h"])
    boxes = diagram.boxes()
    assert len(boxes) == 2 * sum(1 for _ in root.flatten())
    assert overlapping(boxes) == []
    assert diagram.width <= width + 1e-6
    for b in boxes:
        assert b.x >= 0 and b.x + b.w <= width + 1e-6 and b.w > 0 and b.h > 0
        assert b.y >= 0 and b.y + b.h <= diagram.height + 1e-6
    # the text fits its box (measured at the diagram's scale)
    char_w = PRESENTER["char_w"] * diagram.scale
    for n in diagram.nodes:
        assert max(len(s) for s in n.lines) * char_w <= n.box.w + 1e-6
        assert len(n.lines) * diagram.line_h <= n.box.h + 1e-6
        assert max(len(s) for s in n.label_lines) * char_w <= n.label.w + 1e-6


def test_presenter_width_wraps_without_scaling_when_slots_allow():
    scene, root = _tree("cornell-spheres", (32, 32))
    wide = layout(root, _names(scene), 4000.0, char_w=10.5, line_h=20.0)
    assert wide.scale == 1.0
    narrow = layout(root, _names(scene), 480.0, char_w=10.5, line_h=20.0)
    assert narrow.scale <= 1.0 and narrow.width <= 480.0 + 1e-6
    # the wires run from a parent box's bottom down to its child's label
    for (_, y0), (_, y1) in narrow.wires():
        assert y1 > y0


def test_overlap_check_itself():
    assert overlapping([Box(0, 0, 10, 10), Box(5, 5, 10, 10), Box(10, 0, 5, 5)]) == [(0, 1)]


def test_node_at_finds_the_hovered_ray():
    scene, root = _tree("whitted", (48, 28))
    diagram = layout(root, _names(scene), 480.0)
    for n in diagram.nodes:
        b = n.box
        assert diagram.node_at(b.x + b.w / 2, b.y + b.h / 2) is n
    assert diagram.node_at(-5, -5) is None
