"""The live caption (issue 22): the terms found in the lesson's captions, the wrapped layout,
the switch and the values shown under the terms at the probe."""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.lab.caption_terms import (
    TERM_COLORS,
    layout,
    lines_with_terms,
    segments,
    term_value,
    term_value_text,
    terms_in,
    toggle_term,
)
from shadelab.lab.lesson import load_lesson
from shadelab.lab.probe import probe
from shadelab.lab.state import AppState
from shadelab.scene import load_preset


def test_the_lesson_captions_show_their_terms():
    captions = {s.title.split(":")[0]: s.caption for s in load_lesson("phong-to-radiosity").steps}
    assert terms_in(captions["Ambient light"]) == ["ambient"]
    assert terms_in(captions["Diffuse reflection"]) == ["diffuse"]
    assert terms_in(captions["Ambient plus diffuse, with light-source attenuation"]) == \
        ["ambient", "diffuse", "attenuation"]
    assert terms_in(captions["Specular reflection (Phong)"]) == \
        ["ambient", "diffuse", "specular", "attenuation"]
    assert terms_in(captions["Shadows"]) == ["ambient", "diffuse", "specular", "attenuation",
                                            "shadow"]
    assert terms_in(captions["Transparency"]) == []
    spec = captions["Specular reflection (Phong)"]
    pieces = segments(spec)
    assert "".join(p for p, _ in pieces) == spec              # nothing lost or added
    assert ("ks (R . V)^n", "specular") in pieces and ("kd Od (N . L)", "diffuse") in pieces
    # "R = 2 N (N . L) - L" is not the diffuse term: no kd before it
    assert [p for p, t in pieces if t == "diffuse"] == ["kd Od (N . L)"]
    assert set(TERM_COLORS) == {"ambient", "diffuse", "specular", "attenuation", "shadow"}


def test_the_layout_wraps_whole_terms_and_keeps_every_character():
    text = "3/14 Title\nI = Ia ka Od + sum_i S_i f_att,i Ip,i [kd Od (N . L_i) + ks (R_i . V)^n]"
    width = 8.0

    def measure(t):
        return width * len(t)
    for limit in (200.0, 320.0, 800.0):
        runs = layout(text, limit, measure)
        for run in runs:
            assert run.x + measure(run.text.rstrip()) <= limit or run.x == 0.0
        terms = [r for r in runs if r.term]
        assert [r.text for r in terms] == [p for p, t in segments(text) if t]   # never split
        joined = "".join(r.text for r in runs).replace(" ", "")
        assert joined == text.replace("\n", "").replace(" ", "")
        assert runs[0].line == 0 and all(r.line >= 1 for r in runs[1:])    # the title's line
    narrow, wide = layout(text, 200.0, measure), layout(text, 800.0, measure)
    assert max(r.line for r in narrow) > max(r.line for r in wide) == 1
    assert lines_with_terms(wide) == {1}


def test_a_click_switches_a_term_off_and_on_and_asks_for_a_new_probe():
    state = AppState.from_scene(load_preset("lecture"), "lecture")
    state.probe.pixel = (10, 10)
    assert toggle_term(state, "specular") is False
    assert state.view.terms_off == frozenset({"specular"}) and state.probe.requested
    toggle_term(state, "ambient")
    assert toggle_term(state, "specular") is True
    assert state.view.terms_off == frozenset({"ambient"})
    with pytest.raises(ValueError):
        toggle_term(state, "fresnel")


def test_switching_a_term_off_changes_the_probed_total_by_that_term():
    """The caption's value under a term is what leaves the probed I when it is clicked off."""
    scene = load_preset("lecture", ["render.shadows=none", "lights.0.c2=0.2"])
    size = (160, 120)
    found = 0
    for pixel in [(60, 70), (80, 60), (100, 70), (40, 90)]:
        whole = probe(scene, size, pixel, "phong", "phong")
        if whole is None:
            continue
        for term in ("ambient", "diffuse", "specular"):
            without = probe(scene, size, pixel, "phong", "phong", off=(term,))
            value = term_value(whole, term)
            np.testing.assert_allclose(whole.reference - without.reference, value,
                                       rtol=1e-9, atol=1e-12)
            found += float(np.max(value)) > 1e-3
    assert found >= 6
    result = probe(scene, size, (80, 60), "phong", "phong")
    assert term_value_text(result, "ambient", off=True) == "off"
    assert term_value_text(None, "ambient") == ""
    f_att = result.terms.lights[0].f_att
    assert term_value_text(result, "attenuation") == f"{f_att:.2f}"
    assert term_value_text(result, "shadow") == "1.00"


def test_a_screenshots_legend_names_the_terms_switched_off():
    from shadelab.lab.legend import legend_lines

    state = AppState.from_scene(load_preset("lecture"), "lecture")
    assert "terms off" not in legend_lines(state)[0]
    toggle_term(state, "specular")
    toggle_term(state, "ambient")
    assert legend_lines(state)[0].endswith(", terms off: ambient, specular")


def test_the_terms_are_buttons_only_over_a_raster_image():
    from shadelab.lab.caption_terms import terms_switchable
    from shadelab.lab.pipeline_view import set_pipeline

    state = AppState.from_scene(load_preset("lecture"), "lecture")
    assert terms_switchable(state)
    set_pipeline(state, "raytrace")           # the ray tracer draws the whole equation
    assert not terms_switchable(state)
    set_pipeline(state, "gouraud")
    assert terms_switchable(state)
    state.offline.show_radiosity = True       # the solved radiosity meshes, not the raster
    assert not terms_switchable(state)
