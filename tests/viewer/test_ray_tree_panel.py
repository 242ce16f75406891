"""The ray tree in world space survives an orbit (ui/pipelines.poll restarts the ray-traced
viewport's job on any edit, camera included, but keeps the picked tree while the objects,
materials, lights and ray-tracing settings are unchanged); a material edit clears it. The Ray
tree window shows the viewport's tree, else the Offline panel's."""

from __future__ import annotations

import numpy as np

from shadelab.lab.camera_control import orbit
from shadelab.lab.pipeline_view import view_of
from shadelab.lab.state import AppState
from shadelab.scene.preset import load_preset
from shadelab.ui import pipelines
from shadelab.ui.ray_tree_panel import diagram_of, shown_tree

SIZE = (64, 48)
PIXEL = (48, 28)       # the glass sphere of "whitted" at 64x48


class _Runner:
    """A JobRunner stand-in: always busy, no results (poll never starts a worker)."""

    running, started, finished = True, 1.0, 0.0

    def __init__(self):
        self.cancels = 0

    def cancel(self, **_):
        self.cancels += 1

    def snapshot(self):
        return None, 0


def _picked() -> AppState:
    state = AppState.from_scene(load_preset("whitted"), "whitted")
    view = view_of(state)
    view.runner = _Runner()
    pipelines.poll(state, "raytrace", SIZE)
    name, scene, size = view.wanted
    view.job_scene, view.job_size, view.wanted = scene, size, None   # as _start leaves it
    pipelines.pick_ray_tree(state, "raytrace", PIXEL, SIZE)
    assert view.ray_tree is not None and view.ray_tree_pixel == PIXEL
    return state


def test_an_orbit_keeps_the_tree():
    state = _picked()
    view = view_of(state)
    tree = view.ray_tree
    eye = np.array(state.scene.camera.eye, float)
    orbit(state.scene.camera, 40.0, 10.0, 600)
    state.mark_edited()
    assert not np.allclose(state.scene.camera.eye, eye)
    key = view.key
    pipelines.poll(state, "raytrace", SIZE)
    assert view.key != key and view.runner.cancels >= 1      # the image is re-rendered ...
    assert view.ray_tree is tree and view.ray_tree_pixel == PIXEL  # ... the tree stays
    # a new window size too
    pipelines.poll(state, "raytrace", (80, 60))
    assert view.ray_tree is tree


def test_a_material_or_light_edit_clears_the_tree():
    for edit in ("material", "light"):
        state = _picked()
        view = view_of(state)
        view.tree_hover = view.ray_tree
        if edit == "material":
            state.scene.materials["glass"].kt = 0.5
        else:
            state.scene.lights[0].Ip = (0.5, 0.5, 0.5)
        state.mark_edited()
        pipelines.poll(state, "raytrace", SIZE)
        assert view.ray_tree is None and view.ray_tree_pixel is None, edit
        assert view.tree_hover is None


def test_the_window_shows_the_viewport_tree_else_the_offline_one():
    state = AppState.from_scene(load_preset("whitted"), "whitted")
    assert shown_tree(state) == (None, None, None, "")
    state = _picked()
    root, scene, pixel, where = shown_tree(state)
    assert root is view_of(state).ray_tree and where == "viewport" and pixel == PIXEL
    diagram = diagram_of(root, scene, pixel, 480.0)
    assert len(diagram.nodes) == sum(1 for _ in root.flatten())
    assert diagram.nodes[0].title == "glass_sphere"
    view_of(state).ray_tree = None
    state.offline.ray_tree, state.offline.scene, state.offline.ray_tree_pixel = root, scene, (1, 2)
    assert shown_tree(state) == (root, scene, (1, 2), "offline")
