"""Studies: the exact sphere reference in closed form, and the shading study's orderings."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shadelab.cli import main
from shadelab.scene.model import Camera, Light, Material, Object, Scene
from shadelab.studies.shading_study import exact_sphere_image


def _lambert_scene(distance: float = 4.0) -> Scene:
    scene = Scene(Ia=(0.0, 0.0, 0.0))
    scene.camera = Camera(eye=(0.0, 0.0, distance), target=(0.0, 0.0, 0.0), fov_y=40.0)
    scene.lights = [Light(kind="directional", direction=(0.0, 0.0, -1.0), Ip=(1.0, 1.0, 1.0))]
    scene.materials = {"m": Material(ka=0.0, kd=1.0, ks=0.0, Od=(1.0, 1.0, 1.0))}
    scene.objects = [Object(shape="sphere", material="m", radius=1.0)]
    return scene


def test01_exact_sphere_closed_form():
    """Lambert sphere lit from the eye: I = N.L = n_z; the disc covers pi tan^2(a) / (2 t)^2."""
    scene, size = _lambert_scene(), 101
    image, mask = exact_sphere_image(scene, 0, (size, size))
    assert image[50, 50] == pytest.approx([1.0, 1.0, 1.0], abs=1e-4)  # centre: N = L
    assert image[~mask].max() == 0.0
    assert 0.0 <= image.min() and image.max() <= 1.0 + 1e-12
    alpha = math.asin(1.0 / 4.0)                       # silhouette half-angle
    t = math.tan(math.radians(40.0) / 2.0)
    share = math.pi * math.tan(alpha) ** 2 / (2 * t) ** 2
    assert mask.mean() == pytest.approx(share, rel=0.03)


def test02_exact_sphere_rejects_ellipsoids():
    scene = _lambert_scene()
    scene.objects[0].scale = (1.0, 2.0, 1.0)
    with pytest.raises(ValueError):
        exact_sphere_image(scene, 0, (8, 8))


@pytest.fixture(scope="module")
def shading_rows(gl_ctx):
    from shadelab.studies.shading_study import run_shading

    return run_shading(quick=True)


@pytest.mark.gl
def test03_error_falls_with_tessellation(shading_rows):
    result = shading_rows
    for method, rows in result.series().items():
        errors = result.column("relmse", rows)
        assert all(a > b for a, b in zip(errors, errors[1:], strict=False)), (method, errors)
        assert result.column("level", rows) == [0, 1, 2, 3, 4, 5]


@pytest.mark.gl
def test04_phong_beats_gouraud_beats_flat(shading_rows):
    series = shading_rows.series()
    err = {m: shading_rows.column("relmse", rows) for m, rows in series.items()}
    for level in range(1, 6):
        assert err["phong"][level] < err["gouraud"][level] < err["flat"][level]
    assert err["phong"][5] < 1e-5          # exact normals: only the facet depth remains
    assert err["flat"][0] > 100 * err["phong"][5]


@pytest.mark.gl
def test05_result_api_for_the_viewer(shading_rows):
    r = shading_rows
    assert r.x in r.columns and r.y in r.columns and r.group in r.columns
    assert all(len(row) == len(r.columns) for row in r.rows)
    assert all(np.isfinite(float(v)) and float(v) > 0 for v in r.column("time_ms"))


@pytest.mark.gl
def test06_charts_command_writes_png_and_csv(gl_ctx, tmp_path, capsys):
    out = tmp_path / "charts"
    assert main(["charts", "--out", str(out), "--quick", "--only", "shading"]) == 0
    png, csv = out / "shading.png", out / "shading.csv"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size < 200_000
    lines = csv.read_text().splitlines()
    assert lines[0].startswith("method,level,triangles,time_ms") and len(lines) == 19


def test07_charts_bad_input(tmp_path, capsys):
    assert main(["charts", "--only", "nope", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--only 'nope'" in err
    blocker = tmp_path / "file"
    blocker.write_text("x")
    assert main(["charts", "--out", str(blocker)]) == 2
    assert "not a folder" in capsys.readouterr().err


@pytest.mark.gl
def test08_shadow_study_agrees_with_rays_except_zpass_inside(gl_ctx):
    from shadelab.studies.shadow_study import run_shadows

    result = run_shadows(quick=True)
    for row in result.records():
        if row["scene"] == "fail-zpass-eye-inside" and row["method"] == "zpass":
            assert row["mismatch"] > 0.5            # the eye inside a volume inverts z-pass
        else:
            assert row["mismatch"] < 0.02, row      # edge pixels only
        assert row["time_ms"] > 0 and row["oracle_ms"] > 0
    scenes = set(result.column("scene"))
    assert {"shadows", "fail-zpass-eye-inside", "fail-open-caster"} <= scenes


def test09_raytrace_study_depth_and_samples_help():
    from shadelab.studies.raytrace_study import run_raytrace

    result = run_raytrace(quick=True)
    err = {(r["depth"], r["spp"]): r["relmse"] for r in result.records()}
    assert err[(0, 1)] > 2 * err[(2, 1)]          # mirror and glass need secondary rays
    assert err[(4, 4)] < err[(4, 1)]              # more samples: edges converge
    assert all(r["time_ms"] > 0 for r in result.records())


@pytest.mark.gl
def test10_radiosity_study(gl_ctx):
    from shadelab.studies.radiosity_study import run_radiosity

    result = run_radiosity(quick=True)
    rows = result.records()
    err = {(r["series"], r["label"]): r["relmse"] for r in rows}
    assert err[("raycast", "25")] > 2 * err[("raycast", "100")]       # more patches, less error
    assert err[("hemicube-resolution", "8")] > 2 * err[("hemicube-resolution", "32")]
    assert err[("analytic", "100")] > 5 * err[("raycast", "100")]     # ignores the blocks
    direct = err[("solver", "direct")]
    for solver in ("jacobi", "gauss-seidel", "progressive"):
        assert abs(err[("solver", solver)] - direct) < 0.2 * direct     # all converge
    conv = result.extra["convergence"]
    for solver in ("jacobi", "progressive"):
        values = conv.column("residual", conv.series()[solver])
        assert len(values) > 3 and all(b <= a * (1 + 1e-9) for a, b in
                                       zip(values, values[1:], strict=False))


def test11_viewer_registry():
    from shadelab.studies import STUDIES, run_study

    assert [name for name, _ in STUDIES] == ["shading", "raytrace", "radiosity", "shadows"]
    assert all(title for _, title in STUDIES)
    with pytest.raises(KeyError):
        run_study("nope")
