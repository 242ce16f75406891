"""Nothing the viewport draws over an offline image hides the emitter (issue 19.3): the
status box goes to a corner clear of the emitters' projected bounds, and a stand-in light's
gizmo is hidden where the surface it stands for is drawn and does the lighting."""

from __future__ import annotations

from shadelab.lab.pipeline_view import set_pipeline
from shadelab.lab.state import AppState
from shadelab.scene.preset import load_preset
from shadelab.ui import gizmos
from shadelab.ui.pipeline_viewport import emitter_rect, status_place


def _overlap(a, b) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def test_the_cornell_light_projects_to_the_top_middle():
    size = (800, 600)
    x0, y0, x1, y1 = emitter_rect(load_preset("cornell"), size)
    assert 0.3 * size[0] < x0 < x1 < 0.7 * size[0] and 0.1 * size[1] < y0 < y1 < 0.2 * size[1]
    assert emitter_rect(load_preset("cornell", ["materials.light.emission=[0,0,0]"]),
                        size) is None


def test_the_status_box_never_covers_the_emitter():
    size = (800, 600)
    light = emitter_rect(load_preset("cornell"), size)

    def one_line(wrap):       # a long status line in the presenter's font: four rows
        return min(wrap, 700.0), 80.0

    x, y, wrap = status_place(size, one_line, light, readout=90.0)
    w, h = one_line(wrap)
    assert not _overlap((x - 4, y - 2, x + w + 4, y + h + 2), light)
    assert y > size[1] / 2          # the wide box went to the bottom left
    # short text stays top left, clear of the light; no emitter: top left, full width
    assert status_place(size, lambda wrap: (120.0, 20.0), light)[:2] == (8.0, 8.0)
    assert status_place(size, one_line, None, readout=90.0) == (8.0, 8.0, 800 - 16 - 90.0)

    # a viewport too short for a bottom box: top left, wrapped to end before the light
    def tall(wrap):
        return min(wrap, 700.0), 590.0

    x, y, wrap = status_place(size, tall, light)
    assert (x, y) == (8.0, 8.0) and x + tall(wrap)[0] + 4 <= light[0]


def test_a_stand_in_gizmo_is_hidden_where_its_surface_lights_the_scene():
    state = AppState.from_scene(load_preset("cornell"), "cornell")
    light = state.scene.lights[0]
    assert light.stand_in
    assert gizmos.shown(state, light)                  # raster: the stand-in is the light
    for name in ("pathtrace", "radiosity"):
        set_pipeline(state, name)
        assert not gizmos.shown(state, light)
    set_pipeline(state, "raytrace")
    assert gizmos.shown(state, light)
    light.stand_in = False
    set_pipeline(state, "pathtrace")
    assert gizmos.shown(state, light)
