"""The viewer's hemicube and form-factor views (issue 10.4): shadelab.ui.radiosity_view.

GL tests (the hemicube on the headless context) are marked ``gl`` and skip without EGL; the
GUI scenario (the window opens, fills F, the frame keeps coming) is in
tests/gui/test_gui_radiosity_view.py.
"""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.radiosity.formfactors import heatmap_data
from shadelab.radiosity.patches import uniform_patches
from shadelab.scene import load_preset
from shadelab.ui import radiosity_view as rv

RES = 128


@pytest.fixture(scope="module")
def cornell_cube(gl_ctx):
    from shadelab.raster.hemicube import Hemicube

    patches = uniform_patches(load_preset("cornell"), 120)
    cube = Hemicube(patches, RES, ctx=gl_ctx)
    yield patches, cube, cube.rows(np.arange(len(patches)))
    cube.release()


@pytest.mark.gl
def test_face_sums_add_up_to_the_row_sum_of_F(cornell_cube):
    """Per patch, the delta form factors of the five faces' pixels that see a patch sum to
    F's row sum: exactly the same item buffer's row (float rounding), and F as the window
    computes it (another atlas slot) within 1e-4. The whole hemicube's delta factors sum to 1
    within the discretization, 3.3e-5 at 128^2."""
    patches, cube, F = cornell_cube
    for i in range(0, len(patches), 5):
        images = cube.item_images(i)
        view = rv.hemicube_view(images)
        assert view["total"] == pytest.approx(sum(view["face_sums"].values()), abs=1e-12)
        assert view["full"] == pytest.approx(1.0, abs=1e-4)
        row = view["row"].copy()
        row[i] = 0.0
        np.testing.assert_allclose(row, images["row"], atol=1e-12)
        assert view["total"] == pytest.approx(F[i].sum(), abs=1e-4)


@pytest.mark.gl
def test_closed_room_face_sums_are_one(gl_ctx):
    """radiosity-box is closed: every row of F sums to 1, so do the five faces."""
    from shadelab.raster.hemicube import Hemicube

    patches = uniform_patches(load_preset("radiosity-box"), 60)
    cube = Hemicube(patches, RES, ctx=gl_ctx)
    try:
        for i in range(0, len(patches), 7):
            view = rv.hemicube_view(cube.item_images(i))
            assert view["total"] == pytest.approx(1.0, abs=1e-4)
    finally:
        cube.release()


def _seam_agreement(ids: np.ndarray, surface: np.ndarray) -> list[float]:
    """Fraction of pixel pairs across each of the cross's four seams that see the same
    surface (or both nothing)."""
    res = ids.shape[0] // 2
    h = res // 2
    s = np.where(ids >= 0, surface[np.maximum(ids, 0)], -1)
    pairs = [(s[h:h + res, h - 1], s[h:h + res, h]), (s[h - 1, h:h + res], s[h, h:h + res]),
             (s[h:h + res, h + res - 1], s[h:h + res, h + res]),
             (s[h + res - 1, h:h + res], s[h + res, h:h + res])]
    return [float(np.mean(a == b)) for a, b in pairs]


@pytest.mark.gl
def test_unfolded_cross_is_continuous_across_its_seams(cornell_cube):
    """Each side face sits on the top face's edge it shares: across every seam >= 90 % of the
    neighbouring pixels see the same surface (95 % on average, 75 % at worst: a seam
    running along a box's edge). A side laid the wrong way round fails."""
    patches, cube, _ = cornell_cube
    worst_wrong, right = 1.0, []
    for i in range(0, len(patches), 9):
        images = cube.item_images(i)
        right += _seam_agreement(rv.unfold(images["top"], images["sides"]), patches.surface)
        assert min(right[-4:]) >= 0.75, i   # a seam along a box edge: a few pixels off
        wrong = [s[:, ::-1] for s in images["sides"]]
        worst_wrong = min(worst_wrong, min(_seam_agreement(rv.unfold(images["top"], wrong),
                                                           patches.surface)))
    assert np.mean(right) >= 0.95
    assert worst_wrong < 0.6


def test_heatmap_data_is_F_and_its_row_sums():
    rng = np.random.default_rng(3)
    F = rng.random((37, 37)) / 37
    data = heatmap_data(F)
    assert data["matrix"] is F
    np.testing.assert_array_equal(data["row_sums"], F.sum(axis=1))
    assert data["max"] == F.max() and data["min"] == 0.0   # min(initial=0)
    shown, k = rv.block_means(F, most=100)
    assert k == 1 and shown is F                            # small: F itself
    shown, k = rv.block_means(F, most=10)                   # 37 -> blocks of 4, 10 x 10
    assert k == 4 and shown.shape == (10, 10)
    assert shown[0, 0] == pytest.approx(F[:4, :4].mean(), rel=1e-12)
    assert shown[9, 9] == pytest.approx(F[36:, 36:].mean(), rel=1e-12)   # the ragged edge


def test_item_colors_are_distinct_and_nothing_is_dark():
    colors = rv.id_colors(np.arange(2000))
    assert len({tuple(c) for c in colors}) == 2000
    assert tuple(rv.id_colors(np.array([-1]))[0]) == rv.NOTHING


def test_patch_id_soup_round_trips_to_the_item_colors():
    """Linear colors the viewport's sRGB encoding (at exposure 2) turns back into the ids'."""
    from shadelab.shading.conventions import to_srgb8

    polygons = np.arange(5 * 4 * 3, dtype=float).reshape(5, 4, 3)
    soup = rv.patch_id_soup(polygons, exposure=2.0)
    assert soup.shape == (30, 6)
    srgb = to_srgb8(soup[::6, 3:].reshape(1, 5, 3).astype(np.float32), 2.0)[0]
    np.testing.assert_allclose(srgb.astype(int), rv.id_colors(np.arange(5)).astype(int),
                               atol=1)


def test_face_labels_sit_on_their_faces_of_the_unfolded_cross():
    """Each label's box is centred on its own face of the cross unfold() lays out (top in
    the middle, left = +t, back = +b, right = -t, front = -b): the face index at the label's
    centre is that face's."""
    res, side = 16, 320.0
    top = np.zeros((res, res), int)
    sides = [np.full((res // 2, res), k, int) for k in (1, 2, 3, 4)]
    cross = rv.unfold(top, sides, fill=-1)

    def measure(text):
        return 9.0 * len(text), 14.0

    labels = rv.face_label_positions(side, rv.FACES, measure)
    assert [t for *_, t in labels] == ["top", "left", "back", "right", "front"]
    for face, (x, y, text) in enumerate(labels):
        w, h = measure(text)
        cx, cy = x + w / 2, y + h / 2
        assert cross[int(cy / side * 2 * res), int(cx / side * 2 * res)] == face, text


def test_convergence_series_in_percent_with_units():
    x, y, label = rv.convergence_series({"iteration": [1, 2, 3], "unshot": [0.5, 0.1, 0.0],
                                         "residual": [float("nan")] * 3})
    assert list(x) == [1.0, 2.0] and list(y) == [50.0, 10.0]   # 0 cannot go on a log axis
    assert label == "unshot energy (% of emitted)" and rv.axis_label(label) == "unshot (%)"
    x, y, label = rv.convergence_series({"iteration": [1], "unshot": [float("nan")],
                                         "residual": [0.02]})
    assert list(y) == [2.0] and "residual" in label
    assert rv.convergence_series({}) == (None, None, "")


def test_geometry_key_follows_geometry_edits_only():
    from shadelab.scene.preset import clone_scene

    scene = load_preset("cornell")
    key = rv.geometry_key(scene)
    assert rv.geometry_key(clone_scene(scene)) == key       # the job's copy: the same key
    scene.materials["white"].kd = 0.5
    assert rv.geometry_key(scene) == key                    # a material: same patches
    scene.objects[0].vertices = [[552.8, 7.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 559.2],
                                 [549.6, 0.0, 559.2]]
    moved = rv.geometry_key(scene)
    assert moved != key and "7.0" in moved[0]
    scene.radiosity.patches = 123
    assert rv.geometry_key(scene) != moved
