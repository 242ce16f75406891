"""Form factors against closed forms (Howell C-11, C-14), invariants and the hemicube's
delta factors. GL tests (hemicube) are marked ``gl`` and skip without EGL."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shadelab.errors import ShadeLabError
from shadelab.radiosity.formfactors import (
    FormFactors,
    form_factor_matrix,
    heatmap_data,
    hemicube_delta_factors,
    point_polygon,
)
from shadelab.radiosity.patches import from_polygons, uniform_patches
from shadelab.scene.preset import load_preset

PARALLEL = 0.19982  # unit squares, aligned, one unit apart (Howell C-11, X = Y = 1)
PERPENDICULAR = 0.20004  # unit squares sharing an edge at 90 degrees (Howell C-14, W = H = 1)

# Receiver z = 0 facing +z; a parallel one at z = 1 facing -z; a perpendicular one in the
# plane y = 0 facing +y, sharing the edge along x.
FLOOR = [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]
OPPOSITE = [[0, 0, 1], [0, 1, 1], [1, 1, 1], [1, 0, 1]]
WALL = [[0, 0, 0], [0, 0, 1], [1, 0, 1], [1, 0, 0]]


@pytest.fixture(scope="module")
def squares():
    return from_polygons([FLOOR, OPPOSITE, WALL])


def test01_normals_of_the_test_squares(squares):
    np.testing.assert_allclose(squares.normals, [[0, 0, 1], [0, 0, -1], [0, 1, 0]], atol=1e-12)


@pytest.mark.parametrize("method, order, tol", [("raycast", 2, 0.01), ("raycast", 3, 0.001),
                                                ("analytic", 3, 0.001)])
def test02_unit_squares_closed_form(squares, method, order, tol):
    """Ray-cast within 1 % with the default 2x2 receiver points (the issue's bound; 0.7 %
    measured), within 0.1 % with 3x3; analytic within 0.1 %."""
    F = form_factor_matrix(squares, method, order=order)
    assert F[0, 1] == pytest.approx(PARALLEL, rel=tol)
    assert F[0, 2] == pytest.approx(PERPENDICULAR, rel=tol)
    assert F[2, 0] == pytest.approx(PERPENDICULAR, rel=tol)


def test03_point_to_polygon_corner_formula():
    """Point under a corner of an a x b rectangle at distance c (Howell B-3)."""
    a, b, c = 2.0, 1.0, 1.5
    X, Y = a / c, b / c
    exact = (X / math.sqrt(1 + X * X) * math.atan(Y / math.sqrt(1 + X * X))
             + Y / math.sqrt(1 + Y * Y) * math.atan(X / math.sqrt(1 + Y * Y))) / (2 * math.pi)
    rect = [[0, 0, c], [0, b, c], [a, b, c], [a, 0, c]]
    assert point_polygon([0, 0, 0], [0, 0, 1], rect) == pytest.approx(exact, rel=1e-9)
    # A triangle (3 corners) and the same rectangle seen from behind its plane
    assert point_polygon([0, 0, 0], [0, 0, 1], rect[:3]) > 0.0
    assert point_polygon([0, 0, 2 * c], [0, 0, 1], rect) == 0.0


def test04_hemicube_delta_factors_sum_to_one():
    top, side = hemicube_delta_factors(128)
    assert top.shape == (128, 128) and side.shape == (64, 128)
    assert top.sum() + 4 * side.sum() == pytest.approx(1.0, abs=2e-4)
    assert top.max() == top[63, 63] and side[0].sum() > side[-1].sum()


@pytest.fixture(scope="module")
def box_patches():
    return uniform_patches(load_preset("radiosity-box"), 60)


def test05_closed_box_row_sums_and_reciprocity(box_patches):
    """Row sums 1 in a closed room; A_i F_ij = A_j F_ji. Nothing occludes, so the ray-cast
    kernel is the exact one: every receiver point sees exactly the whole room (row sums to
    1e-6); reciprocity errs only by the 2x2 receiver quadrature, worst (4.7 %) for
    perpendicular neighbours whose edges overlap in part, 0.28 % summed over all pairs."""
    F = np.stack([FormFactors(box_patches, "raycast").row(i) for i in range(len(box_patches))])
    data = heatmap_data(F)
    np.testing.assert_allclose(data["row_sums"], 1.0, atol=1e-6)
    AF = box_patches.areas[:, None] * F
    np.testing.assert_allclose(AF, AF.T, rtol=0.06, atol=1e-12)
    assert np.abs(AF - AF.T).sum() / AF.sum() < 0.005
    # The full matrix is made reciprocal; its row sums keep within the quadrature error
    full = form_factor_matrix(box_patches, "raycast")
    np.testing.assert_allclose(full.sum(axis=1), 1.0, atol=0.01)
    assert np.all(np.diag(F) == 0.0)


def test06_reciprocity_with_occlusion():
    """With a block in the room the visible share is sampled by rays (4 receiver points x 4
    rays per pair), from each side separately, so reciprocity holds only up to that sampling:
    4.2 % summed over pairs at 59 patches (measured; bound 6 %). Away from the floor, which
    the block hides in part, the room is closed: row sums 1 within 0.03."""
    patches = uniform_patches(load_preset("radiosity-leak"), 80)
    ff = FormFactors(patches, "raycast")
    F = ff.compute_rows(np.arange(len(patches)))  # each row from its own patch
    AF = patches.areas[:, None] * F
    assert np.abs(AF - AF.T).sum() / AF.sum() < 0.06
    off_floor = patches.centers[:, 1] > 1e-9
    np.testing.assert_allclose(F.sum(axis=1)[off_floor], 1.0, atol=0.03)


def test07_rows_on_demand_and_the_reciprocal_matrix(box_patches):
    """A row on demand (progressive refinement) integrates over its own patch; the full
    matrix integrates each pair over the smaller patch and is reciprocal to rounding. The
    two agree within the quadrature error (5 % worst, see test05)."""
    ff = FormFactors(box_patches, "raycast")
    row = ff.row(7).copy()
    full = FormFactors(box_patches, "raycast").matrix()
    np.testing.assert_allclose(row, full[7], rtol=0.06, atol=1e-12)
    AF = box_patches.areas[:, None] * full
    np.testing.assert_allclose(AF, AF.T, rtol=1e-12, atol=1e-15)


@pytest.mark.gl
def test08_hemicube_unit_squares(gl_ctx, squares):
    """A 256^2 hemicube at 3x3 Gauss points per receiver: within 2 % (the issue's bound).
    (One hemicube at the centre measures the point factor instead: 0.239, +20 %.)"""
    from shadelab.raster.hemicube import Hemicube

    F = FormFactors(squares, "hemicube", resolution=256, hemicube_samples=9,
                    hemicube=Hemicube).matrix()
    assert F[0, 1] == pytest.approx(PARALLEL, rel=0.02)
    assert F[0, 2] == pytest.approx(PERPENDICULAR, rel=0.02)
    centre = FormFactors(squares, "hemicube", resolution=256, hemicube=Hemicube).matrix()
    assert centre[0, 1] == pytest.approx(point_polygon([0.5, 0.5, 0], [0, 0, 1], OPPOSITE),
                                         rel=0.01)


@pytest.mark.gl
def test09_hemicube_closed_box(gl_ctx, box_patches):
    """Row sums 1 within 1 % (pixels cover the whole hemisphere); agrees with ray-cast
    within 0.01 per entry at 128^2 (patches are small next to their distances)."""
    from shadelab.raster.hemicube import Hemicube

    F = FormFactors(box_patches, "hemicube", resolution=128, hemicube=Hemicube).matrix()
    np.testing.assert_allclose(F.sum(axis=1), 1.0, atol=0.01)
    ray = form_factor_matrix(box_patches, "raycast")
    far = ~np.isclose(box_patches.normals @ box_patches.normals.T, 0.0)  # not perpendicular
    assert np.abs(F - ray)[far].max() < 0.02


@pytest.mark.gl
def test10_item_images_of_a_patch(gl_ctx, box_patches):
    """The teaching images: ids on the 5 faces; summing delta factors per id gives the row."""
    from shadelab.raster.hemicube import Hemicube

    cube = Hemicube(box_patches, 32)
    images = cube.item_images(3)
    assert images["top"].shape == (32, 32) and len(images["sides"]) == 4
    assert images["sides"][0].shape == (16, 32)
    ids = np.concatenate([images["top"].ravel()] + [s.ravel() for s in images["sides"]])
    dF = np.concatenate([images["top_dF"].ravel()] + [images["side_dF"].ravel()] * 4)
    assert ids.min() >= 0  # a closed room: every pixel sees a patch
    row = np.bincount(ids, weights=dF, minlength=len(box_patches))
    row[3] = 0.0
    np.testing.assert_allclose(row, images["row"], atol=1e-12)
    cube.release()


def test11_hemicube_without_a_backend_is_refused(squares):
    """The radiosity layer imports no GL: hemicube form factors need the backend passed in."""
    from shadelab.errors import ShadeLabError
    from shadelab.radiosity.solution import iter_radiosity

    with pytest.raises(ShadeLabError, match="hemicube=shadelab.raster.hemicube.Hemicube"):
        FormFactors(squares, "hemicube")
    with pytest.raises(ShadeLabError, match="GPU backend"):
        next(iter_radiosity(load_preset("cornell"), None, 20, "hemicube"))


@pytest.mark.gl
def test_a_hemicube_past_the_gl_limit_is_one_line(gl_ctx, tmp_path, capsys):
    """hemicube_resolution 4096 (the schema's maximum): a 20480-px atlas that llvmpipe's
    16384-px limit cannot hold; before, moderngl's 'framebuffer is not complete' traceback."""
    from shadelab.cli import main
    from shadelab.raster.hemicube import check_resolution, gl_size_limit

    limit = gl_size_limit(gl_ctx)
    check_resolution(gl_ctx, limit // 5 // 2 * 2)  # the largest that fits is accepted
    with pytest.raises(ShadeLabError, match=f"exceed this GL's limit of {limit} px"):
        check_resolution(gl_ctx, limit // 5 // 2 * 2 + 2)
    out = tmp_path / "x.png"
    code = main(["radiosity", "cornell", "-o", str(out), "--size", "16x16",
                 "--form-factors", "hemicube", "--set", "radiosity.hemicube_resolution=4096"])
    err = capsys.readouterr().err
    assert code == 2 and "hemicube_resolution 4096" in err and "Traceback" not in err
    assert not out.exists()


def test12_culling_changes_no_form_factor(monkeypatch):
    """Shaft culling drops pairs whose shaft crosses no surface inside its box, and casts
    no rays where one surface stands across the whole shaft (visibility 0): on the Cornell
    box (its two blocks hide much of the room) the matrix is the one whose every pair is
    ray-cast, with under 60 % of the rays (measured 1.77 M of 4.40 M at 1029 patches). The
    only differences are grazing pairs of F ~ 1e-9 whose rays skim a surface (measured
    1.9e-9 at most): bound 1e-7 of the largest factor."""
    from shadelab.radiosity import formfactors
    from shadelab.radiosity.meshing import discontinuity_patches

    patches = discontinuity_patches(load_preset("cornell"), 250)
    rays = {}

    def counted(key):
        def occluded(self, origins, dirs):
            rays[key] = rays.get(key, 0) + len(origins)
            return original(self, origins, dirs)
        return occluded

    original = FormFactors._occluded
    monkeypatch.setattr(FormFactors, "_occluded", counted("culled"))
    culled = FormFactors(patches, "raycast").matrix()
    blockable = formfactors._blockable
    monkeypatch.setattr(formfactors, "_blockable",
                        lambda pairs, *args: np.ones(len(pairs), np.int8))
    monkeypatch.setattr(FormFactors, "_occluded", counted("every"))
    every = FormFactors(patches, "raycast").matrix()
    np.testing.assert_allclose(culled, every, rtol=0.0, atol=1e-7 * every.max())
    assert rays["culled"] < 0.6 * rays["every"]
    print(f"\nrays {rays['culled']} of {rays['every']}, "
          f"largest difference {np.abs(culled - every).max():.2e}")
    # the shortcut is taken: some pairs are wholly blocked, and their factor is 0
    planes, planar, lo, hi, inward, sides, eps = FormFactors(patches, "raycast")._occluders()
    i, j = np.nonzero(every > 0.0)
    code = blockable(np.stack([i, j], axis=1).astype(np.int64), patches.polygons,
                     patches.surface, planes, planar, lo, hi, inward, sides, eps)
    assert (code == 2).sum() == 0  # a pair with F > 0 is never wholly blocked
    i, j = np.nonzero((every == 0.0) & (patches.normals @ patches.normals.T < 0.5))
    code = blockable(np.stack([i, j], axis=1).astype(np.int64), patches.polygons,
                     patches.surface, planes, planar, lo, hi, inward, sides, eps)
    assert (code == 2).sum() > 100
