"""GUI tests of the presenter-ready viewer (issue 11): layout with nothing cut off at
1024x768 and 1920x1080 in presenter mode, a lesson walk-through, a light gizmo drag, preset
loads that undo, overlays cleared on scene change, the native file dialogs (stubbed at their
boundary, ``shadelab.ui.dialogs.BACKEND``) and a panel error that closes its ImGui scopes.

Each scenario runs in its own process under a private Xvfb (large enough for 1920x1080).
Run one by hand:  xvfb-run -s "-screen 0 1920x1080x24" python3 tests/gui/test_gui_presenter.py \
    layout_1024 /tmp/out
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
SIZES = {"layout_1024": (1024, 768), "layout_1920": (1920, 1080)}
WINDOW_SIZES = SIZES | {"caption_glyphs_1920": (1920, 1080)}
DOCK_WINDOWS = ("Scene", "Lights", "Materials", "Objects", "Equation & probe", "Offline render")
# every panel, for the content-width check (text carries no item id: only the window's content
# size shows a line of text that runs past the right edge)
ALL_PANELS = DOCK_WINDOWS + ("Algorithms", "Studies", "Failure gallery", "Hemicube & F",
                             "Ray tree")


@pytest.fixture(scope="module")
def bigdisplay():
    """A private Xvfb screen that holds a 1920x1080 window."""
    yield from private_xvfb("1984x1144x24")


def _run(name, display, tmp_path):
    return run_scenario(name, display, tmp_path, script=__file__, timeout=150)


@pytest.mark.parametrize("name", sorted(SIZES))
def test_presenter_layout_cuts_nothing_off(bigdisplay, tmp_path, name):
    r = _run(name, bigdisplay, tmp_path)
    assert r["display"] == list(SIZES[name])
    assert set(r["checked"]) == set(DOCK_WINDOWS)
    for label in DOCK_WINDOWS:
        if label != "Equation & probe":  # its text and table rows carry no item ids
            assert r["checked"][label] >= 3, f"{label}: too few items seen"
    assert r["clipped"] == [], f"items past their window's right edge: {r['clipped'][:8]}"
    assert set(r["content_checked"]) == set(ALL_PANELS)
    assert r["too_wide"] == [], f"content (text, tables) wider than the panel: {r['too_wide']}"
    assert len(r["tabs"]) >= len(ALL_PANELS)
    narrow = [t for t in r["tabs"] if t[1] < t[2] - 1]
    assert narrow == [], f"dock tabs shrunk below their title (or '{TAB_WORD}'): {narrow}"
    # Tab: every panel hidden, the viewport fills the window and carries the caption
    assert r["hidden_visible"] == []
    assert r["presenter_viewport"][0] >= SIZES[name][0] - 2
    assert "I = " in r["caption"] and "Phong" in r["caption"]
    assert r["shown_again"] == sorted(DOCK_WINDOWS + ("Viewport",)) or \
        set(DOCK_WINDOWS) <= set(r["shown_again"])


def test_caption_glyphs_keep_their_size_through_a_lesson_walk(bigdisplay, tmp_path):
    r = _run("caption_glyphs_1920", bigdisplay, tmp_path)
    assert r["font_scale_main"] == pytest.approx(1.8)
    assert len(set(r["px"])) == 1, f"caption font px changed between steps: {r['px']}"
    assert len(set(r["lines"])) == 1, f"caption line height changed: {r['lines']}"
    assert r["lines"][0] >= r["px"][0] - 1
    # the glyph drawn: its quad height and its height in the atlas ("G" at the caption size)
    glyphs = {(g[0], g[1], g[2]) for g in r["glyphs"]}
    assert len(glyphs) == 1, f"caption glyph changed size between steps: {r['glyphs']}"
    quad, baked, in_atlas = glyphs.pop()
    assert baked == r["px"][0] and quad == in_atlas and quad >= 0.5 * baked
    # one band for the lesson: the image keeps its height from step to step
    assert len(set(r["viewport_heights"])) == 1, r["viewport_heights"]


def test_caption_glyphs_keep_their_size_through_a_resized_walk(bigdisplay, tmp_path):
    r = _run("caption_glyphs_resized", bigdisplay, tmp_path)
    assert r["sizes"][-1] == [1920, 1080]
    assert len(set(r["px"])) == 1, f"caption font px changed between steps: {r['px']}"
    assert r["px"][0] == pytest.approx(r["expected"][0], abs=1.0)


def test_lesson_walks_forward_and_back(bigdisplay, tmp_path):
    from shadelab.lab.lesson import load_lesson

    lesson = load_lesson("phong-to-radiosity")
    r = _run("lesson_walk", bigdisplay, tmp_path)
    assert r["presets"] == [Path(s.preset).stem for s in lesson.steps]
    assert r["captions"] == [s.caption for s in lesson.steps]
    assert r["indices"] == list(range(len(lesson.steps)))
    assert r["after_page_up"] == len(lesson.steps) - 2
    assert r["toggles"] == [sorted(s.show) for s in lesson.steps]
    assert any(s.show for s in lesson.steps)
    assert r["ambient_light_enabled"] is False and r["ambient_shadows"] == "none"
    assert r["errors"] == [""] * len(lesson.steps)
    # the caption band under the image is drawn (dark), not the bare window: ImGuizmo once
    # hid it when the light stood beside the eye, as in the first step
    from PIL import Image

    x0, y0, x1, y1 = r["band_strip"]
    strip = np.asarray(Image.open(tmp_path / "lesson.png").convert("L"))[y0:y1, x0:x1]
    assert strip.size and np.median(strip) < 24, np.median(strip)


def test_gizmo_drag_moves_the_light_by_the_dragged_distance(bigdisplay, tmp_path):
    r = _run("gizmo_drag", bigdisplay, tmp_path)
    moved = np.subtract(r["after"], r["before"])
    # The camera looks down -z: a 60 px drag to the right moves the light along +x by
    # 60 pixels' worth of world length at its depth, and not in y or z.
    expected = 60 * r["pixel_size"]
    assert moved[0] == pytest.approx(expected, rel=0.05)
    assert abs(moved[1]) < 0.05 * expected and abs(moved[2]) < 0.05 * expected
    assert r["camera_unchanged"]          # the drag did not orbit the camera
    assert r["undo_steps"] == 1           # one drag, one undo step
    assert r["undone"] == pytest.approx(r["before"])


def test_a_lesson_is_picked_and_stepped_from_the_scene_panel(bigdisplay, tmp_path):
    r = _run("lesson_panel", bigdisplay, tmp_path)
    assert r["picked"] == ["phong-to-radiosity", 0, "normals"]   # step 1 shown
    assert r["after_next"] == 1 and r["scene_after_next"] == "lecture"
    assert r["after_prev"] == 0
    assert r["after_none"] is None and r["scene_after_none"] == "normals"


def test_the_cameras_framing_is_edited_live_from_the_display_section(bigdisplay, tmp_path):
    r = _run("camera_framing", bigdisplay, tmp_path)
    assert r["fov_y"] == pytest.approx(60.0) and r["fit_aspect"] == pytest.approx(1.5)
    assert r["title"].endswith("*")            # scene fields: the unsaved marker shows


def test_preset_load_undo_and_overlays_cleared(bigdisplay, tmp_path):
    r = _run("hygiene", bigdisplay, tmp_path)
    assert r["loaded"] == "cornell" and r["undone"] == "lecture" and r["redone"] == "cornell"
    assert r["title_after_undo"] == "ShadeLab - lecture"      # the first file, unedited
    assert r["asked"] == "cornell" and r["kept_after_cancel"] == "lecture"
    assert r["edits_kept_after_cancel"] == 0.123
    assert r["overlays_before"] == [True, True]
    assert r["overlays_after_camera_move"] == [True, True]  # a view change keeps them
    assert r["overlays_after_edit"] == [False, False]
    assert r["camera_undo"]                                  # Ctrl+Z leaves the camera


def test_file_dialogs_stubbed_and_a_panel_error_closes_its_scopes(bigdisplay, tmp_path):
    r = _run("dialogs", bigdisplay, tmp_path)
    assert r["asked"][0][:2] == ["open_file", "Open a preset or mesh"]
    assert r["opened"] == "cornell"
    assert r["saved_exists"] and r["saved_kd"] == 0.5
    assert r["mesh_objects"] == r["objects_before"] + 1
    assert r["cancel_status"] == "mesh: cancelled"
    assert r["dropped"] == "shadows"
    assert "boom" in r["panel_error"] and r["frames_after_error"] >= 5


TAB_WORD = "Materials"   # (shadelab.ui.app.TAB_WORD; the pytest side imports no GUI)


# ---------------------------------------------------------------- scenario side


OUT_DIR = "."


def _check_layout(ctx, state, out: dict) -> None:
    from imgui_bundle import imgui
    from imgui_bundle.immapp import testing  # noqa: F401  (the engine's context)

    state.view.presenter = True
    state.probe.pixel, state.probe.requested = (200, 200), True
    ctx.yield_(10)  # fonts, the one-column layout and the probe settle
    for _ in range(600):  # the Offline panel lists its renderers once a thread found them
        if state.offline.kinds is not None:
            break
        ctx.yield_()
    ctx.yield_(2)
    out["display"] = [int(imgui.get_io().display_size.x), int(imgui.get_io().display_size.y)]
    ctx.window_focus("//Scene")
    ctx.item_open("//Scene/Display and presenter")   # its rows are checked too
    ctx.yield_(2)
    clipped, checked = [], {}
    for label in DOCK_WINDOWS:
        ctx.window_focus(f"//{label}")
        ctx.yield_(4)
        window = ctx.get_window_by_ref(f"//{label}")
        items = imgui.test_engine.TestItemList()
        ctx.gather_items(items, f"//{label}", -1)
        inner = window.inner_clip_rect
        count = 0
        for k in range(items.get_size()):
            item = items.get_by_index(k)
            rect = item.rect_full
            if rect.max.y < inner.min.y or rect.min.y > inner.max.y:
                continue  # scrolled out of view vertically (panels scroll)
            count += 1
            if rect.max.x > inner.max.x + 1.0 or rect.min.x < inner.min.x - 1.0:
                clipped.append([label, ctx.item_info(item.id_).debug_label
                                if hasattr(ctx.item_info(item.id_), "debug_label")
                                else str(item.id_),
                                round(rect.min.x), round(rect.max.x), round(inner.max.x)])
        checked[label] = count
    out["clipped"], out["checked"] = clipped, checked
    too_wide, content_checked = [], []
    for label in ALL_PANELS:
        ctx.window_focus(f"//{label}")
        ctx.yield_(4)   # the content size is measured at the end of a frame drawn in front
        window = ctx.get_window_by_ref(f"//{label}")
        region = window.content_region_rect
        width = region.max.x - region.min.x
        content_checked.append(label)
        if window.content_size.x > width + 1.0:
            too_wide.append([label, round(window.content_size.x), round(width)])
    out["too_wide"], out["content_checked"] = too_wide, content_checked
    from shadelab.ui.app import TAB_WORD

    word = imgui.calc_text_size(TAB_WORD).x
    tabs, seen = [], set()
    for label in ALL_PANELS:   # dock tabs: as wide as their title or the word, then scroll
        node = ctx.get_window_by_ref(f"//{label}").dock_node
        if node is None or node.tab_bar is None or node.id_ in seen:
            continue
        seen.add(node.id_)
        for k in range(node.tab_bar.tabs.size()):
            tab = node.tab_bar.tabs[k]
            tabs.append([tab.window.name if tab.window else "?", round(tab.width),
                         round(min(tab.content_width, word))])
    out["tabs"] = tabs
    capture(ctx, str(Path(OUT_DIR) / "presenter.png"))
    ctx.key_press(imgui.Key.tab)
    ctx.yield_(5)
    from imgui_bundle import hello_imgui

    from shadelab.ui.presenter import caption_text

    windows = hello_imgui.get_runner_params().docking_params.dockable_windows
    out["hidden_visible"] = [w.label for w in windows if w.is_visible]
    out["presenter_viewport"] = list(state.view.viewport_size)
    out["caption"] = caption_text(state)
    capture(ctx, str(Path(OUT_DIR) / "presenter-tab.png"))
    ctx.key_press(imgui.Key.tab)
    ctx.yield_(5)
    out["shown_again"] = sorted(w.label for w in windows if w.is_visible)


def scenario_layout_1024(ctx, state, out: dict) -> None:
    _check_layout(ctx, state, out)


def scenario_layout_1920(ctx, state, out: dict) -> None:
    _check_layout(ctx, state, out)


def scenario_lesson_walk(ctx, state, out: dict) -> None:
    from imgui_bundle import imgui

    from shadelab.lab.lesson import LessonRun, go_to, load_lesson

    state.walk.lesson = LessonRun(load_lesson("phong-to-radiosity"))
    go_to(state, 0)
    ctx.yield_(3)
    from shadelab.lab.lesson_file import SHOW_TOGGLES

    presets, captions, indices, errors, toggles = [], [], [], [], []
    for i in range(len(state.walk.lesson.lesson.steps)):
        if i:
            ctx.key_press(imgui.Key.page_down)
            ctx.yield_(3)
        presets.append(state.scene.name)
        captions.append(state.walk.lesson.step.caption)
        indices.append(state.walk.lesson.index)
        errors.append(state.error)
        toggles.append(sorted(name for name, attr in SHOW_TOGGLES.items()
                              if getattr(state.view, attr)))
        if state.walk.lesson.step.title == "Ambient light":   # the light is off: Ia ka alone
            out["ambient_light_enabled"] = state.scene.lights[0].enabled
            out["ambient_shadows"] = state.scene.render.shadows
        if i == 0:   # the normals step: its light sits beside the eye (the gizmo is skipped)
            ctx.yield_(3)
            capture(ctx, str(Path(OUT_DIR) / "lesson.png"))
            region = ctx.get_window_by_ref("//Viewport").content_region_rect
            bottom = int(region.max.y)
            out["band_strip"] = [int(region.min.x) + 4, bottom - 10, int(region.max.x) - 4,
                                 bottom - 6]
    ctx.key_press(imgui.Key.page_down)  # past the end: stays on the last step
    ctx.yield_(2)
    ctx.key_press(imgui.Key.page_up)
    ctx.yield_(3)
    out["after_page_up"] = state.walk.lesson.index
    out.update(presets=presets, captions=captions, indices=indices, errors=errors,
               toggles=toggles)


def scenario_gizmo_drag(ctx, state, out: dict) -> None:
    from imgui_bundle import imgui

    from shadelab.ui import gizmos

    state.scene.camera.eye, state.scene.camera.target = (0.0, 1.0, 6.0), (0.0, 1.0, 0.0)
    state.scene.lights[0].position = (0.5, 1.2, 0.0)
    state.mark_edited()
    state.view.show_fps = False
    ctx.yield_(6)
    steps_before = state.history.index
    before = list(state.scene.lights[0].position)
    camera = tuple(state.scene.camera.eye)
    info = ctx.item_info("//Viewport/viewport_input")
    origin = info.rect_full.min
    size = state.view.viewport_size
    project, _, _ = gizmos.projector(state, size)
    x, y = project(before)
    start = imgui.ImVec2(origin.x + x, origin.y + y)
    ctx.mouse_move_to_pos(start)
    ctx.yield_(2)
    ctx.mouse_down(0)
    ctx.yield_(2)
    for k in range(1, 7):
        ctx.mouse_move_to_pos(imgui.ImVec2(start.x + 10 * k, start.y))
        ctx.yield_(1)
    ctx.yield_(2)
    ctx.mouse_up(0)
    ctx.yield_(4)
    out["before"], out["after"] = before, list(state.scene.lights[0].position)
    out["pixel_size"] = gizmos.pixel_size_at(state, before, size[1], size[0])
    out["camera_unchanged"] = tuple(state.scene.camera.eye) == camera
    out["undo_steps"] = state.history.index - steps_before
    state.undo()
    ctx.yield_(2)
    out["undone"] = list(state.scene.lights[0].position)


def scenario_lesson_panel(ctx, state, out: dict) -> None:
    """No --lesson: the Scene panel's Lesson combo starts one, the buttons under the
    viewport's caption step it (they stay in reach whichever panel a step brings forward)."""
    from imgui_bundle import imgui

    state.view.presenter = True
    ctx.yield_(5)
    ctx.window_focus("//Scene")
    ctx.set_ref("//Scene")
    ctx.item_click("Lesson")
    # the first step brings the Objects panel forward, hiding the Scene tab under the cursor:
    # no hover check after the click
    ctx.item_click("//$FOCUSED/phong-to-radiosity", 0,
                   imgui.test_engine.TestOpFlags_.no_check_hovered_id)
    ctx.yield_(4)
    run = state.walk.lesson
    out["picked"] = [Path(run.lesson.path).stem, run.index, state.scene.name]
    ctx.set_ref("//Viewport")
    ctx.item_click("Next > (PgDn)")
    ctx.yield_(3)
    out["after_next"], out["scene_after_next"] = state.walk.lesson.index, state.scene.name
    ctx.item_click("< Prev (PgUp)")
    ctx.yield_(3)
    out["after_prev"] = state.walk.lesson.index
    capture(ctx, str(Path(OUT_DIR) / "lesson-buttons.png"))
    ctx.window_focus("//Scene")
    ctx.set_ref("//Scene")
    ctx.item_click("Lesson")
    ctx.item_click("//$FOCUSED/(none)")
    ctx.yield_(3)
    out["after_none"], out["scene_after_none"] = state.walk.lesson, state.scene.name


def scenario_camera_framing(ctx, state, out: dict) -> None:
    ctx.yield_(3)
    ctx.window_focus("//Scene")
    ctx.set_ref("//Scene")
    ctx.item_open("Display and presenter")
    ctx.item_input_value("field of view", 60.0)
    ctx.item_input_value("fit aspect", 1.5)
    ctx.yield_(3)
    cam = state.scene.camera
    out["fov_y"], out["fit_aspect"], out["title"] = cam.fov_y, cam.fit_aspect, state.title()


def scenario_hygiene(ctx, state, out: dict) -> None:
    from imgui_bundle import imgui

    from shadelab.scene.preset import clone_scene

    ctx.yield_(3)
    state.request_open("cornell")  # no edits: opens at once
    ctx.yield_(3)
    out["loaded"] = state.scene.name
    ctx.key_press(int(imgui.Key.mod_ctrl) | int(imgui.Key.z))
    ctx.yield_(3)
    out["undone"], out["title_after_undo"] = state.scene.name, state.title()
    ctx.key_press(int(imgui.Key.mod_ctrl) | int(imgui.Key.y))
    ctx.yield_(3)
    out["redone"] = state.scene.name
    ctx.key_press(int(imgui.Key.mod_ctrl) | int(imgui.Key.z))
    ctx.yield_(3)
    # unsaved edits: opening asks; Cancel keeps the scene and the edits
    state.scene.materials["plastic"].kd = 0.123
    state.mark_edited()
    ctx.yield_(3)
    state.request_open("cornell")
    ctx.yield_(3)
    out["asked"] = state.pending_open
    ctx.item_click("//Discard unsaved changes?/Cancel")
    ctx.yield_(3)
    out["kept_after_cancel"] = state.scene.name
    out["edits_kept_after_cancel"] = state.scene.materials["plastic"].kd
    # overlays belong to the scene the job rendered
    state.offline.scene = clone_scene(state.scene)
    state.offline.radiosity_soup = np.zeros((3, 6), np.float32)
    state.offline.ray_tree = object()
    ctx.yield_(3)
    out["overlays_before"] = [state.offline.radiosity_soup is not None,
                              state.offline.ray_tree is not None]
    state.offline.ray_tree = None  # (a dummy tree cannot be drawn; a real one is a RayNode)
    ctx.set_ref("//Viewport")
    eye = tuple(state.scene.camera.eye)
    ctx.item_drag_with_delta("viewport_input", imgui.ImVec2(50, 0))
    ctx.yield_(3)
    state.offline.ray_tree = "tree"  # stands for a tree: only its presence is checked below
    state.scene_version += 1
    ctx.yield_(2)
    out["overlays_after_camera_move"] = [state.offline.radiosity_soup is not None,
                                         state.offline.ray_tree is not None]
    moved_eye = tuple(state.scene.camera.eye)
    state.offline.ray_tree = None
    state.scene.materials["plastic"].kd = 0.3
    state.mark_edited()
    ctx.yield_(3)
    out["overlays_after_edit"] = [state.offline.radiosity_soup is not None,
                                  state.offline.ray_tree is not None]
    ctx.key_press(int(imgui.Key.mod_ctrl) | int(imgui.Key.z))
    ctx.yield_(3)
    out["camera_undo"] = moved_eye != eye and tuple(state.scene.camera.eye) == moved_eye


class _Dialog:
    def __init__(self, answer):
        self.answer = answer

    def ready(self, timeout=0):
        return True

    def result(self):
        return self.answer


class StubBackend:
    """portable_file_dialogs stand-in: answers from a queue, records what was asked."""

    def __init__(self, answers):
        self.answers, self.asked = list(answers), []

    def open_file(self, title, default_path="", filters=None, options=None):
        self.asked.append(["open_file", title])
        return _Dialog([self.answers.pop(0)] if self.answers[0] else [])

    def save_file(self, title, default_path="", filters=None, options=None):
        self.asked.append(["save_file", title])
        return _Dialog(self.answers.pop(0))


def scenario_dialogs(ctx, state, out: dict) -> None:
    import trimesh

    from shadelab.scene.preset import load_preset
    from shadelab.ui import dialogs, lights_panel

    mesh_path = Path(OUT_DIR) / "tet.obj"
    trimesh.creation.icosphere(1).export(mesh_path)
    saved = Path(OUT_DIR) / "mine.toml"
    from shadelab.scene.preset import resolve_preset

    stub = StubBackend([str(resolve_preset("cornell")), str(saved), str(mesh_path), ""])
    dialogs.BACKEND = stub
    ctx.yield_(3)
    ctx.window_focus("//Scene")
    ctx.set_ref("//Scene")
    ctx.item_click("Open...")
    ctx.yield_(3)
    out["opened"] = state.scene.name
    state.scene.materials["white"].kd = 0.5
    state.mark_edited()
    ctx.yield_(2)
    ctx.item_click("Save as...")
    ctx.yield_(3)
    out["saved_exists"] = saved.is_file()
    out["saved_kd"] = load_preset(str(saved)).materials["white"].kd if saved.is_file() else None
    out["objects_before"] = len(state.scene.objects)
    ctx.item_click("Add mesh...")
    ctx.yield_(3)
    out["mesh_objects"] = len(state.scene.objects)
    ctx.item_click("Add mesh...")
    ctx.yield_(3)
    out["cancel_status"] = state.status
    out["asked"] = stub.asked
    # drag and drop: the window's drop callback queues the files
    state.save_as(str(saved))  # nothing unsaved, so the drop opens without asking
    dialogs.on_drop([str(resolve_preset("shadows"))])
    ctx.yield_(3)
    out["dropped"] = state.scene.name
    # an exception inside an open ImGui scope (a tree node of the Lights panel)

    original = lights_panel._light_rows

    def broken(light, span):
        raise UnicodeDecodeError("utf-8", b"\xff", 0, 1, "boom")

    lights_panel._light_rows = broken
    ctx.window_focus("//Lights")
    ctx.yield_(5)
    out["panel_error"] = state.error
    lights_panel._light_rows = original
    frame = state.frame
    ctx.yield_(5)
    out["frames_after_error"] = state.frame - frame


def scenario_caption_glyphs_1920(ctx, state, out: dict) -> None:
    """Presenter mode at 1920x1080: the whole lesson walked without restart, the caption's
    font size and line height at every step (issue 22: glyphs came out small after a few
    steps), then the same step opened fresh."""
    from imgui_bundle import imgui

    from shadelab.lab.lesson import LessonRun, go_to, load_lesson
    from shadelab.ui import presenter

    presenter.RECORD_CAPTION = True   # the caption's sizes, drawn frame by frame
    state.view.presenter = True
    ctx.yield_(5)
    state.walk.lesson = LessonRun(load_lesson("phong-to-radiosity"))
    go_to(state, 0)
    ctx.yield_(4)
    px, lines, bands, glyphs = [], [], [], []
    for i in range(len(state.walk.lesson.lesson.steps)):
        if i:
            ctx.key_press(imgui.Key.page_down)
            ctx.yield_(4)
        px.append(presenter.drawn_caption["px"])
        lines.append(presenter.drawn_caption["line"])
        bands.append(state.view.viewport_size[1])
        glyphs.append([presenter.drawn_caption[k] for k in ("glyph", "baked", "uv", "atlas")])
        if i in (7, 8):   # "8/14 Multiple", "Gouraud": the captions once drawn small
            capture(ctx, str(Path(OUT_DIR) / f"caption-step{i + 1}.png"))
    ctx.key_press(imgui.Key.page_up)
    ctx.yield_(4)
    px.append(presenter.drawn_caption["px"])
    lines.append(presenter.drawn_caption["line"])
    out.update(px=px, lines=lines, viewport_heights=bands, glyphs=glyphs,
               font_scale_main=imgui.get_style().font_scale_main)


def scenario_caption_glyphs_resized(ctx, state, out: dict) -> None:
    """The way a lecture goes: a few steps at the desk (1280x720), presenter mode on, a few
    more, the window to 1920x1080, the rest and back: the caption's font px per step."""
    import glfw
    from imgui_bundle import glfw_utils, imgui

    from shadelab.lab.lesson import LessonRun, go_to, load_lesson
    from shadelab.ui import presenter

    presenter.RECORD_CAPTION = True   # the caption's sizes, drawn frame by frame
    state.walk.lesson = LessonRun(load_lesson("phong-to-radiosity"))
    go_to(state, 0)
    ctx.yield_(4)
    px, expected, sizes = [], [], []
    steps = len(state.walk.lesson.lesson.steps)
    for i in range(1, steps):
        if i == 3:
            state.view.presenter = True
        if i == 6:
            glfw.set_window_size(glfw_utils.glfw_window_hello_imgui(), 1920, 1080)
        ctx.key_press(imgui.Key.page_down)
        ctx.yield_(4)
        if i >= 3:
            px.append(presenter.drawn_caption["px"])
            expected.append(presenter.caption_font_px(presenter.caption_scale(state)))
            sizes.append([int(imgui.get_io().display_size.x), int(imgui.get_io().display_size.y)])
    for _ in range(steps - 1):
        ctx.key_press(imgui.Key.page_up)
        ctx.yield_(3)
        px.append(presenter.drawn_caption["px"])
    out.update(px=px, expected=expected, sizes=sizes)


def _main(name: str, out_dir: str) -> int:
    global OUT_DIR
    OUT_DIR = out_dir
    return run_scenario_main(globals(), name, out_dir, "lecture",
                             WINDOW_SIZES.get(name, (1280, 720)), autosave=False)


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1], sys.argv[2]))
