"""GUI tests of the labels in the scene (issue 22, items 3-4) at 1024x768: the kd-grid's five
values drawn under five spheres that all stay in the viewport, the kd = 0 sphere set off from
its background, the probe's arrow names and its sum and GPU value in the viewport's corner;
the normals step's heat map and its legend in the colours of the scale.

Run one by hand:  xvfb-run -s "-screen 0 1100x850x24" python3 tests/gui/test_gui_labels.py \
    kd_grid /tmp/out
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from test_gui import run_scenario  # noqa: E402

from gui_harness import capture, private_xvfb, run_scenario_main  # noqa: E402

pytestmark = pytest.mark.gui
WINDOW = (1024, 768)
PRESETS = {"kd_grid": "kd-grid", "normals_step": "lecture"}


@pytest.fixture(scope="module")
def display():
    yield from private_xvfb(f"{WINDOW[0] + 64}x{WINDOW[1] + 64}x24")


def _run(name, display, tmp_path):
    return run_scenario(name, display, tmp_path, script=__file__, timeout=150)


def _image(tmp_path, name) -> np.ndarray:
    return np.asarray(Image.open(tmp_path / name).convert("RGB")).astype(int)


def _crop(image, rect):
    x0, y0, x1, y1 = (int(round(v)) for v in rect)
    return image[y0:y1, x0:x1]


def test_kd_grid_values_probe_arrows_and_readout_are_drawn(display, tmp_path):
    r = _run("kd_grid", display, tmp_path)
    image = _image(tmp_path, "kd-grid.png")
    ox, oy = r["origin"]
    w, h = r["size"]
    values = [p for p in r["plates"] if p[0].startswith("kd = ")]
    assert [p[0] for p in values] == ["kd = 0", "kd = 0.25", "kd = 0.5", "kd = 0.75", "kd = 1"]
    for text, x0, y0, x1, y1 in r["plates"]:
        assert ox <= x0 and x1 <= ox + w and oy <= y0 and y1 <= oy + h, text  # in the view
        plate = _crop(image, (x0, y0, x1, y1))
        assert (plate.max(axis=2) > 150).sum() >= 6, f"{text}: no text on its plate"
        assert (plate.max(axis=2) < 60).mean() > 0.3, f"{text}: no dark plate"
    # each value sits under its sphere: the plates' centres run left to right, one per sphere
    centres = [0.5 * (p[1] + p[3]) for p in values]
    assert centres == sorted(centres) and min(np.diff(centres)) > 40
    # the kd = 0 sphere is black, its surroundings are not
    x, y = r["sphere0"]
    disc = _crop(image, (x - 5, y - 5, x + 5, y + 5))
    assert disc.max() <= 6
    around = image[int(y), int(r["sphere0_left"]) - 12]
    assert around.min() >= 40
    # the probe: its arrows named at their heads, its sum and the GPU's value in the corner
    assert {p[0] for p in r["plates"]} >= {"N", "V", "L", "R"}
    terms, rect = r["readout"]
    assert terms[-2].startswith("= I") and terms[-1] == "GPU drew"
    assert rect[0] >= ox and rect[3] <= oy + h                       # inside the viewport
    readout = _crop(image, rect)
    green = (readout[..., 1] > 180) & (readout[..., 0] < 160)       # "agrees" in green
    assert green.sum() >= 20
    assert r["gpu_agrees"]


def test_the_normals_step_paints_the_heat_map_with_its_legend(display, tmp_path):
    from shadelab.lab.overlays import heat_color_srgb

    r = _run("normals_step", display, tmp_path)
    image = _image(tmp_path, "normals-step.png")
    title, full, bar = r["legend"]
    assert title == "angle average vs area" and full == 40.0      # 37.4 degrees, rounded up
    x0, y0, x1, y1 = bar
    row = int(round(0.5 * (y0 + y1)))
    for t in (0.1, 0.5, 0.9):
        x = int(round(x0 + t * (x1 - x0)))
        np.testing.assert_allclose(image[row, x] / 255.0, heat_color_srgb(t), atol=0.06)
    # the pyramid's apex is the hottest vertex: the pixel just under it is near the top
    # of the scale (yellow), the middle of the fan's base near its bottom (dark)
    ax, ay = r["apex"]
    apex = image[int(ay) + 6, int(ax)] / 255.0
    assert apex[0] > 0.8 and apex[1] > 0.6 and apex[2] < 0.7, apex
    assert r["glyphs"] == {"face": r["faces"], "vertex": r["vertices"]}


# ---------------------------------------------------------------- scenario side


def scenario_kd_grid(ctx, state, out: dict) -> None:
    from shadelab.geometry.mesh import scene_meshes
    from shadelab.lab import labels
    from shadelab.ui import scene_labels

    ctx.yield_(4)
    size = state.view.viewport_size
    meshes = scene_meshes(state.scene)
    box = labels.screen_box(state.scene, meshes[2], size)   # kd = 0.5, the middle sphere
    state.probe.pixel = (int(0.5 * (box[0] + box[2]) - 0.2 * (box[2] - box[0])),
                         int(0.5 * (box[1] + box[3]) - 0.2 * (box[3] - box[1])))
    state.probe.requested = True
    for _ in range(40):
        ctx.yield_(1)
        if state.probe.result is not None and not state.probe.requested:
            break
    ctx.yield_(3)
    drawn = scene_labels.drawn
    ox, oy = drawn["origin"]
    zero = labels.screen_box(state.scene, meshes[0], size)
    result = state.probe.result
    out.update(origin=[ox, oy], size=list(drawn["size"]), plates=drawn["plates"],
               readout=drawn["readout"],
               sphere0=[ox + 0.5 * (zero[0] + zero[2]), oy + 0.5 * (zero[1] + zero[3])],
               sphere0_left=ox + zero[0],
               gpu_agrees=bool(np.max(np.abs(result.gpu - result.reference)) < 1e-4))
    capture(ctx, str(Path(OUT_DIR) / "kd-grid.png"))


def scenario_normals_step(ctx, state, out: dict) -> None:
    from shadelab.geometry.mesh import scene_meshes
    from shadelab.lab import labels, overlays
    from shadelab.lab.lesson import LessonRun, go_to, load_lesson
    from shadelab.ui import scene_labels

    state.walk.lesson = LessonRun(load_lesson("phong-to-radiosity"))
    go_to(state, 0)
    ctx.yield_(6)
    assert state.view.show_normal_diff and state.view.show_face_normals
    drawn = scene_labels.drawn
    ox, oy = drawn["origin"]
    meshes = scene_meshes(state.scene)
    pyramid = meshes[1]
    apex = pyramid.vertices[int(np.argmax(pyramid.vertices[:, 1]))]
    ax, ay = labels.to_pixels(state.scene, state.view.viewport_size, apex)
    length = 0.1
    faces = sum(len(m.faces) for m in meshes)
    vertices = sum(len(np.unique(m.faces)) for m in meshes)   # smooth: one normal a vertex
    out.update(legend=drawn["legend"], apex=[ox + ax, oy + ay],
               faces=faces, vertices=vertices,
               glyphs={"face": len(overlays.face_normal_glyphs(meshes, length)) // 2,
                       "vertex": len(overlays.vertex_normal_glyphs(meshes, length)) // 2})
    state.view.show_face_normals = state.view.show_normals = False   # the apex unhidden
    state.view.show_wireframe = False
    ctx.yield_(4)
    capture(ctx, str(Path(OUT_DIR) / "normals-step.png"))


def _main(name: str, out_dir: str) -> int:
    global OUT_DIR
    OUT_DIR = out_dir
    return run_scenario_main(globals(), name, out_dir, PRESETS[name], WINDOW, autosave=False)


if __name__ == "__main__":
    sys.exit(_main(sys.argv[1], sys.argv[2]))
