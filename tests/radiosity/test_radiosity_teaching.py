"""Radiosity at lecture pace (issue 19.1): the viewer's shot-by-shot job as the lesson's
Radiosity step runs it (shadelab.pipelines.radiosity.pipeline_radiosity).

* ``radiosity.ambient``: after the first shot, a patch the shooter does not see is black
  without the ambient estimate and rho * ambient with it (Cohen et al. 1988, eq. 5, in closed
  form here);
* the rows of F the job sends (``stats["ff_rows"]``) are the rows the solver shot with, so the
  Hemicube & F window can show them; with ``form_factors = "hemicube"`` they are the GPU
  hemicube's (the job makes its own GL context);
* the display's cached plan gives :func:`display_meshes`' values.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from shadelab.pipelines import radiosity as pipeline
from shadelab.radiosity import display
from shadelab.radiosity.formfactors import FormFactors
from shadelab.radiosity.patches import split_leaves, uniform_patches
from shadelab.scene import load_preset
from shadelab.shading.packing import reflectance

PATCHES = 100


def _cornell(**settings):
    scene = load_preset("cornell")
    scene.radiosity.patches = PATCHES
    for key, value in settings.items():
        setattr(scene.radiosity, key, value)
    return scene


def _first_shot(scene):
    pipeline._RADIOSITY_CACHE.clear()
    for progress in pipeline.pipeline_radiosity(scene, None, step_shots=1):
        if progress.stats.get("shots") == 1:
            return progress
    raise AssertionError("no first shot")


def _rho_emission(scene, patches):
    rho, emission = np.zeros((len(patches), 3)), np.zeros((len(patches), 3))
    for index, surface in enumerate(patches.surfaces):
        material = scene.materials[surface.material]
        rho[patches.surface == index] = reflectance(material)
        emission[patches.surface == index] = material.emission
    return rho, emission


@pytest.mark.parametrize("ambient", [False, True])
def test_first_shot_with_and_without_the_ambient_estimate(ambient):
    """Cornell's light patch shoots first (the point light is a stand-in). After that shot:
    B_j = E_j + rho_j dB_i F_ij A_i / A_j (+ rho_j * ambient when on), with
    ambient = sum_k unshot_k A_k / sum_k A_k / (1 - rho_avg), rho_avg the area-weighted
    reflectance: the closed form of the estimate, computed here from the shooter's row."""
    scene = _cornell(ambient=ambient)
    first = _first_shot(scene)
    patches = uniform_patches(scene, PATCHES)
    i = first.stats["shooter_index"]
    rho, emission = _rho_emission(scene, patches)
    E = math.pi * emission
    assert E[i].max() > 0                                   # the light shot first
    row = FormFactors(patches, "raycast").row(i)
    areas = patches.areas
    gain = rho * E[i][None, :] * (row * areas[i] / areas)[:, None]
    unshot = E + gain
    unshot[i] = 0.0
    rho_avg = (rho * areas[:, None]).sum(0) / areas.sum()
    estimate = (unshot * areas[:, None]).sum(0) / areas.sum() / (1.0 - rho_avg)
    B = first.stats["B"]
    np.testing.assert_allclose(first.stats["ambient"], estimate, rtol=1e-10)
    expected = E + gain + (rho * estimate if ambient else 0.0)
    np.testing.assert_allclose(B, expected, rtol=1e-9, atol=1e-9)
    dark = (row == 0.0) & (E.max(axis=1) == 0.0)             # unseen by the light, no emitter
    assert dark.sum() >= 10
    if ambient:
        np.testing.assert_allclose(B[dark], rho[dark] * estimate, rtol=1e-9)
        assert B[dark].min() > 0.0                          # the room looks lit already
    else:
        assert np.all(B[dark] == 0.0)                       # only the shot's light
    assert first.stats["ambient_shown"] is ambient
    # the display triangles: black where every patch around is black (ambient off)
    radiance = first.stats["soup"][:, 3:]
    assert (radiance.max() > 0) and ((radiance == 0).all(axis=1).any() != ambient)


def _all_rows(progresses) -> dict:
    rows = {}
    for p in progresses:
        idx, values = p.stats.get("ff_rows", (np.zeros(0, int), None))
        for k, i in enumerate(idx):
            assert int(i) not in rows, "a row is sent once"
            rows[int(i)] = values[k]
    return rows


def test_the_rows_sent_are_the_rows_the_solver_shot_with():
    """Every shooter's row arrives in ``ff_rows`` (sent once), equal to the row of the
    reciprocal matrix the form-factor engine computes (the one every solver reads); a second
    job on the same geometry sends every known row
    in its first Progress (the window may have missed none)."""
    scene = _cornell(tolerance=0.05)
    pipeline._RADIOSITY_CACHE.clear()
    seen = list(pipeline.pipeline_radiosity(scene, None, step_shots=1))
    rows = _all_rows(seen)
    shooters = {p.stats["shooter_index"] for p in seen if "shooter_index" in p.stats}
    assert len(shooters) > 5 and shooters <= set(rows)
    patches = uniform_patches(scene, PATCHES)
    matrix = FormFactors(patches, "raycast").matrix()
    for i in sorted(shooters)[:8]:
        np.testing.assert_allclose(rows[i], matrix[i], rtol=1e-12, atol=1e-15)
    assert seen[-1].stats["form_factors"] == "raycast"
    again = list(pipeline.pipeline_radiosity(scene, None, step_shots=1))
    assert again[0].stats["form_factors_reused"]
    assert set(_all_rows(again[:1])) == set(rows)


@pytest.mark.gl
def test_hemicube_form_factors_in_the_job_are_the_gpu_hemicubes(gl_ctx):
    """``form_factors = "hemicube"``: the job renders hemicubes (its own GL context in the
    process running it), several likely shooters per atlas; each row sent equals
    Hemicube.rows of that patch to the atlas slot's rasterization (1e-4, as the window's
    item images) and sums like it; the stats name the method and resolution."""
    from shadelab.raster.hemicube import Hemicube

    scene = _cornell(form_factors="hemicube", tolerance=0.05)
    pipeline._RADIOSITY_CACHE.clear()
    seen = list(pipeline.pipeline_radiosity(scene, None))
    last = seen[-1].stats
    assert last["form_factors"] == "hemicube" and last["form_factors_label"] == \
        "hemicube 128x128" and "form_factors_note" not in last
    rows = _all_rows(seen)
    patches = uniform_patches(scene, PATCHES)
    cube = Hemicube(patches, 128, ctx=gl_ctx)
    try:
        for i in list(rows)[:6]:
            np.testing.assert_allclose(rows[i], cube.rows(np.array([i]))[0], atol=1e-4)
    finally:
        cube.release()
    assert last["done"] and last["history"]["unshot"][-1] < 0.05


@pytest.mark.parametrize("split", [False, True])
def test_display_plan_equals_display_meshes(split):
    """The viewer job's cached display plan gives display_meshes' vertices, faces and values
    (uniform Cornell grid; and with T-vertices from split leaves, fans included)."""
    scene = load_preset("cornell")
    patches = uniform_patches(scene, 150)
    if split:
        patches = split_leaves(scene, patches, np.arange(0, len(patches), 4))
    radiance = np.random.default_rng(3).random((len(patches), 3))
    expected = display.display_meshes(patches, radiance)
    got = display.DisplayPlan(patches).meshes(radiance)
    assert len(got) == len(expected)
    for (v0, f0, c0), (v1, f1, c1) in zip(expected, got, strict=True):
        np.testing.assert_array_equal(f0, f1)
        np.testing.assert_allclose(v0, v1, rtol=0, atol=1e-12)
        np.testing.assert_allclose(c0, c1, rtol=1e-12, atol=1e-12)


def test_first_lit_image_comes_before_the_form_factor_matrix():
    """The lesson's first lit image waits for one row, not all of F: the job's first Progress
    after meshing is the first shot (a preview, before any form-factor progress), and the
    solve that follows, once F is known, shoots that same first shot (Cornell's light is the
    smaller patch of every pair, so the reciprocal matrix's row is the row integrated over it:
    the same B to rounding)."""
    scene = _cornell()
    pipeline._RADIOSITY_CACHE.clear()
    seen = list(pipeline.pipeline_radiosity(scene, None))
    assert seen[0].message == "meshing"
    preview = seen[1]
    assert preview.stats["preview"] is True and preview.stats["shots"] == 1
    assert len(preview.stats["soup"]) > 0 and preview.stats["soup"][:, 3:].max() > 0
    later = [p.message for p in seen[2:]]
    assert any(m.startswith("form factors") for m in later)   # F is computed after it
    solved = next(p for p in seen[2:] if p.stats.get("shots") == 1)
    assert "preview" not in solved.stats
    assert solved.stats["shooter_index"] == preview.stats["shooter_index"]
    np.testing.assert_allclose(preview.stats["B"], solved.stats["B"], rtol=1e-12, atol=1e-12)
    # a second job on the same geometry knows F already: no preview; nor in step mode
    # (each press of Step shoots one shot of the solve itself)
    again = list(pipeline.pipeline_radiosity(scene, None))
    assert not any(p.stats.get("preview") for p in again)
    pipeline._RADIOSITY_CACHE.clear()
    stepped = list(pipeline.pipeline_radiosity(scene, None, step_shots=1))
    assert not any(p.stats.get("preview") for p in stepped)
