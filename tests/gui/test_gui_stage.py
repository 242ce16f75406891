"""GUI tests of the stage (issue 22, "the viewport is the stage"): presenter mode at 1024x768 and
1920x1080 walks the whole lesson without restart; the viewport (image and caption band) takes
at least 75 % of the window, the caption band and the controls strip keep one height, the
caption's glyphs one size, the strip shows each step's controls and edits the scene with undo,
Tab brings the panels and back, and a click on a caption term switches exactly that term's
contribution off in the image (the GPU's probed pixel) and on again.

Each scenario runs in its own process under a private Xvfb (large enough for 1920x1080).
Run one by hand:  xvfb-run -s "-screen 0 1920x1080x24" python3 tests/gui/test_gui_stage.py \
    stage_1024 /tmp/out
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from test_gui import run_scenario  # noqa: E402

from gui_harness import capture, private_xvfb, run_scenario_main  # noqa: E402

pytestmark = pytest.mark.gui
SIZES = {"stage_1024": (1024, 768), "stage_1920": (1920, 1080)}
SHARE = 0.75          # the viewport's least share of the window (image + caption band)
SPECULAR_STEP = 5     # "Specular reflection (Phong)": ambient, f_att, diffuse, specular


@pytest.fixture(scope="module")
def bigdisplay():
    yield from private_xvfb("1984x1144x24")


@pytest.mark.parametrize("name", sorted(SIZES))
def test_the_stage_through_a_whole_lesson(bigdisplay, tmp_path, name):
    from shadelab.lab.lesson import load_lesson

    steps = load_lesson("phong-to-radiosity").steps
    r = run_scenario(name, bigdisplay, tmp_path, script=__file__, timeout=300)
    width, height = SIZES[name]
    assert r["display"] == [width, height]
    assert r["errors"] == [""] * len(steps)
    # no dock window over the stage: neither a tab focused at start nor a step's focus
    assert r["visible"] == [[]] * len(steps), r["visible"]
    # the viewport is the stage: image + caption band >= 75 % of the window, at every step
    assert len(r["shares"]) == len(steps)
    assert min(r["shares"]) >= SHARE, r["shares"]
    assert min(r["image_shares"]) == max(r["image_shares"])
    # the scene never moves: one image size, one caption band, one strip for the lesson
    assert len({tuple(s) for s in r["viewport_sizes"]}) == 1, r["viewport_sizes"]
    assert r["viewport_sizes"][0][0] >= width - 2
    assert len(set(r["bands"])) == 1 and r["bands"][0] > 0, r["bands"]
    assert len(set(r["strips"])) == 1 and r["strips"][0] > 0, r["strips"]
    # the caption's glyphs keep one size through the walk
    assert len(set(r["caption_px"])) == 1, r["caption_px"]
    assert len({tuple(g) for g in r["glyphs"]}) == 1, r["glyphs"]
    assert r["caption_px"][0] >= 1.4 * 1.8 * 12          # large: presenter x caption scale
    # the strip shows each step's named controls, as the widgets the fields want
    assert r["strip_paths"] == [s.controls for s in steps]
    assert r["strip_widgets"][SPECULAR_STEP] == ["slider", "slider", "slider"]
    assert r["strip_widgets"][9] == ["combo", "checkbox", "combo"]      # shadows
    # a strip edit is a scene edit with its undo step
    assert r["strip_edit"] == [55.0, 1, r["strip_before"]]
    # Tab: every panel back (no strip there); Tab again: the stage
    assert "Materials" in r["tab_panels"] and r["tab_strip"] == 0.0
    assert r["tab_back"] == [] and r["tab_back_strip"] == r["strips"][0]
    # the live caption: the specular step's terms drawn as buttons, values under them
    assert set(r["terms_drawn"]) == {"ambient", "diffuse", "specular", "attenuation"}
    assert all(r["term_values"][t] for t in ("ambient", "diffuse", "specular")), r["term_values"]


@pytest.mark.parametrize("name", sorted(SIZES))
def test_a_click_on_a_caption_term_switches_exactly_that_term(bigdisplay, tmp_path, name):
    """The GPU's probed pixel drops by the probe's value of the term clicked off (float32 GPU
    vs float64 numpy: 1e-4 relative, 2e-5 absolute) and comes back when clicked on."""
    r = run_scenario(name.replace("stage", "terms"), bigdisplay, tmp_path, script=__file__,
                     timeout=300)
    before = np.array(r["gpu_before"])
    assert before.max() > 0.05
    for term in ("ambient", "diffuse", "specular"):
        got = before - np.array(r["gpu_off"][term])
        expected = np.array(r["term_value"][term])
        assert expected.max() > 0.01, (term, expected)          # a term worth switching
        np.testing.assert_allclose(got, expected, rtol=1e-4, atol=2e-5, err_msg=term)
        np.testing.assert_allclose(r["reference_off"][term], before - expected, rtol=1e-4,
                                   atol=2e-5)
        np.testing.assert_allclose(r["gpu_on"][term], before, rtol=1e-5, atol=1e-6)
        assert r["off_sets"][term] == [term]
    # f_att off: every light unattenuated, I grows (f_att < 1 here)
    assert np.all(np.array(r["gpu_off"]["attenuation"]) >= before - 1e-6)
    assert r["caption_values_off"] == "off"
    assert r["off_after_step"] == []                           # the next step: every term on


# ---------------------------------------------------------------- scenario side


OUT_DIR = "."


def _start_stage(ctx, state) -> None:
    from shadelab.lab.lesson import LessonRun, go_to, load_lesson
    from shadelab.ui import presenter, stage

    presenter.RECORD_CAPTION = True
    stage.RECORD = True
    presenter.set_presenter(state, True)
    state.walk.lesson = LessonRun(load_lesson("phong-to-radiosity"))
    go_to(state, 0)
    ctx.yield_(6)


def _probe_pixel(state) -> tuple[int, int]:
    """A pixel on the plastic sphere where ambient, diffuse and specular all count."""
    from shadelab.lab.probe import probe
    from shadelab.ui import gizmos

    size = state.view.viewport_size
    obj = next(o for o in state.scene.objects if o.material == "plastic")
    project, _, _ = gizmos.projector(state, size)
    cx, cy = project(obj.translate)
    best, best_pixel = -1.0, (int(cx), int(cy))
    for dx in range(-30, 31, 6):
        for dy in range(-30, 31, 6):
            pixel = (int(cx + dx), int(cy + dy))
            result = probe(state.scene, size, pixel)
            if result is None or result.hit.mesh.material != "plastic":
                continue
            spec = sum(float(np.min(t.specular)) for t in result.terms.lights)
            if spec > best and spec < 0.5 * float(np.min(result.reference)):
                best, best_pixel = spec, pixel
    return best_pixel


def _walk(ctx, state, out: dict) -> None:
    from imgui_bundle import hello_imgui, imgui

    from shadelab.lab.caption_terms import term_value_text
    from shadelab.ui import presenter, stage

    _start_stage(ctx, state)
    io = imgui.get_io()
    width, height = int(io.display_size.x), int(io.display_size.y)
    out["display"] = [width, height]
    steps = len(state.walk.lesson.lesson.steps)
    keys = ("shares", "image_shares", "viewport_sizes", "bands", "strips", "caption_px",
            "glyphs", "strip_paths", "strip_widgets", "errors", "visible")
    rec = {k: [] for k in keys}
    for i in range(steps):
        if i:
            ctx.key_press(imgui.Key.page_down)
            ctx.yield_(4)
        w, h = state.view.viewport_size
        band = presenter.caption_band(state, width)
        strip = stage.strip_height(state)
        rec["viewport_sizes"].append([w, h])
        rec["bands"].append(round(band, 2))
        rec["strips"].append(round(strip, 2))
        rec["shares"].append(round(w * (h + band) / (width * height), 4))
        rec["image_shares"].append(round(w * h / (width * height), 4))
        rec["caption_px"].append(presenter.drawn_caption["px"])
        rec["glyphs"].append([presenter.drawn_caption[k] for k in ("glyph", "baked")])
        rec["strip_paths"].append([p for p, _, _ in stage.drawn_controls])
        rec["strip_widgets"].append([w for _, w, _ in stage.drawn_controls])
        rec["errors"].append(state.error)
        windows = hello_imgui.get_runner_params().docking_params.dockable_windows
        rec["visible"].append(sorted(w.label for w in windows if w.is_visible))
        if i == SPECULAR_STEP:
            state.probe.pixel, state.probe.requested = _probe_pixel(state), True
            ctx.yield_(4)
            out["terms_drawn"] = sorted(presenter.drawn_terms)
            out["term_values"] = {t: term_value_text(state.probe.result, t)
                                  for t in presenter.drawn_terms}
            size = "x".join(map(str, (width, height)))
            capture(ctx, str(Path(OUT_DIR) / f"presenter-strip-{size}.png"))
            # a strip edit: the specular exponent of the plastic, through its slider
            ident = next(d for p, _, d in stage.drawn_controls if p == "materials.plastic.n")
            out["strip_before"] = state.scene.materials["plastic"].n
            undo_before = state.history.index
            ctx.item_input_value(ident, 55.0)
            ctx.yield_(4)
            n_after, steps_after = state.scene.materials["plastic"].n, state.history.index
            state.undo()
            ctx.yield_(3)
            out["strip_edit"] = [n_after, steps_after - undo_before,
                                 state.scene.materials["plastic"].n]
            # Tab: the dock panels, no strip; Tab: the stage again
            windows = hello_imgui.get_runner_params().docking_params.dockable_windows
            ctx.key_press(imgui.Key.tab)
            ctx.yield_(5)
            out["tab_panels"] = sorted(w.label for w in windows if w.is_visible)
            out["tab_strip"] = stage.strip_height(state)
            ctx.key_press(imgui.Key.tab)
            ctx.yield_(5)
            out["tab_back"] = sorted(w.label for w in windows if w.is_visible)
            out["tab_back_strip"] = round(stage.strip_height(state), 2)
            state.probe.pixel = None
            state.probe.result = None
            ctx.yield_(2)
    out.update(rec)


def _click_term(ctx, term: str) -> None:
    from imgui_bundle import imgui

    from shadelab.ui import presenter

    x0, y0, x1, y1 = presenter.drawn_terms[term][1]
    ctx.mouse_move_to_pos(imgui.ImVec2((x0 + x1) / 2, (y0 + y1) / 2))
    ctx.mouse_click(0)
    ctx.yield_(4)


def _toggle_terms(ctx, state, out: dict) -> None:
    from imgui_bundle import imgui

    from shadelab.lab.caption_terms import term_value, term_value_text
    from shadelab.lab.lesson import go_to
    from shadelab.ui import presenter

    _start_stage(ctx, state)
    go_to(state, SPECULAR_STEP)
    ctx.yield_(6)
    state.probe.pixel, state.probe.requested = _probe_pixel(state), True
    ctx.yield_(4)
    before = state.probe.result
    out["gpu_before"] = before.gpu.tolist()
    gpu_off, gpu_on, ref_off, values, sets = {}, {}, {}, {}, {}
    for term in ("ambient", "diffuse", "specular", "attenuation"):
        values[term] = np.asarray(term_value(before, term)).tolist()
        _click_term(ctx, term)
        gpu_off[term] = state.probe.result.gpu.tolist()
        ref_off[term] = state.probe.result.reference.tolist()
        sets[term] = sorted(state.view.terms_off)
        if term == "specular":
            out["caption_values_off"] = term_value_text(state.probe.result, term, True)
            size = "x".join(str(int(v)) for v in (imgui.get_io().display_size.x,
                                                  imgui.get_io().display_size.y))
            capture(ctx, str(Path(OUT_DIR) / f"presenter-specular-off-{size}.png"))
        _click_term(ctx, term)
        gpu_on[term] = state.probe.result.gpu.tolist()
    out.update(gpu_off=gpu_off, gpu_on=gpu_on, reference_off=ref_off, term_value=values,
               off_sets=sets)
    _click_term(ctx, "ambient")
    ctx.key_press(imgui.Key.page_down)
    ctx.yield_(4)
    out["off_after_step"] = sorted(state.view.terms_off)
    assert presenter.drawn_terms  # (the scenario's own sanity: the caption was drawn)


def scenario_stage_1024(ctx, state, out: dict) -> None:
    _walk(ctx, state, out)


def scenario_stage_1920(ctx, state, out: dict) -> None:
    _walk(ctx, state, out)


def scenario_terms_1024(ctx, state, out: dict) -> None:
    _toggle_terms(ctx, state, out)


def scenario_terms_1920(ctx, state, out: dict) -> None:
    _toggle_terms(ctx, state, out)


def _main(name: str, out_dir: str) -> int:
    global OUT_DIR
    OUT_DIR = out_dir
    size = SIZES.get(name) or SIZES[name.replace("terms", "stage")]
    return run_scenario_main(globals(), name, out_dir, "lecture", size, autosave=False)


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1], sys.argv[2]))
