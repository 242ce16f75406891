"""``radiosity.meshing``: the setting, its flag, and what the default gives on the Cornell box.

The default (discontinuity meshing: hidden cells dropped, cells across the light's shadow
boundaries split) is held to the bench's goal: within 1.5 % of the converged path-traced
reference at the bench's size (:data:`shadelab.bench.radiosity.ERROR_SIZE`, 32 x 32), with the
bench's metric (relative L1 away from the light, 16 x 16 sub-pixels). The reference is the
bench's own 16k-spp image (two 8192-spp seeds averaged, :func:`converged_reference`), stored
in ``data/`` (12 KB) so the test does not spend the minutes it takes to render; its own noise
is ~0.6 %.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from shadelab.bench.radiosity import ERROR_SIZE, SUPERSAMPLE, emitter_ring_mask, image_error
from shadelab.errors import ShadeLabError
from shadelab.radiosity.solution import resolve_meshing, solve_scene
from shadelab.scene.preset import load_preset, save_preset

REFERENCE = Path(__file__).parent / "data" / "cornell-32x32-16kspp.npy"
GOAL = 0.015  # the bench's goal (radiosity_error_in_2s); measured 1.43 % (1029 patches)


@pytest.mark.parametrize("meshing", ["uniform", "adaptive", "discontinuity"])
def test_the_setting_round_trips_through_a_preset_and_set(meshing, tmp_path):
    scene = load_preset("cornell", [f"radiosity.meshing={meshing}"])
    assert scene.radiosity.meshing == meshing
    path = tmp_path / "m.toml"
    save_preset(scene, path)
    assert load_preset(str(path)).radiosity.meshing == meshing


def test_a_bad_meshing_is_one_line():
    with pytest.raises(ShadeLabError, match="meshing"):
        load_preset("cornell", ["radiosity.meshing=voronoi"])


def test_the_default_is_discontinuity_and_adaptive_false_means_a_grid():
    scene = load_preset("cornell")
    assert scene.radiosity.meshing == "discontinuity"
    assert resolve_meshing(scene, None) == "discontinuity"
    assert resolve_meshing(scene, None, adaptive=False) == "uniform"
    assert resolve_meshing(scene, "adaptive", adaptive=False) == "uniform"
    assert resolve_meshing(scene, "discontinuity", adaptive=False) == "discontinuity"


@pytest.mark.parametrize("meshing", ["uniform", "adaptive", "discontinuity"])
def test_the_job_uses_the_setting(meshing):
    scene = load_preset("cornell", [f"radiosity.meshing={meshing}", "radiosity.patches=60",
                                    "radiosity.solver=gauss-seidel"])
    solution = solve_scene(scene)
    assert solution.stats["meshing"] == meshing
    assert solution.patches.info.get("meshing", "uniform") == \
        ("discontinuity" if meshing == "discontinuity" else "uniform")


def test_the_cli_flag_sets_the_meshing(monkeypatch, tmp_path):
    from shadelab import pipelines
    from shadelab.cli import main

    seen = {}

    def stop(scene, *args, **kwargs):
        seen["meshing"] = scene.radiosity.meshing
        raise ShadeLabError("stopped here")

    monkeypatch.setattr(pipelines.get("radiosity"), "run", stop)
    out = str(tmp_path / "r.png")
    assert main(["radiosity", "cornell", "-o", out, "--meshing", "adaptive"]) == 2
    assert seen["meshing"] == "adaptive"
    assert main(["radiosity", "cornell", "-o", out, "--uniform"]) == 2
    assert seen["meshing"] == "uniform"
    assert main(["radiosity", "cornell", "-o", out]) == 2
    assert seen["meshing"] == "discontinuity"


def test_the_default_meshing_on_cornell_is_within_the_goal():
    """``shadelab radiosity cornell`` at its defaults against the converged reference."""
    scene = load_preset("cornell")
    reference = np.load(REFERENCE)
    assert reference.shape == (ERROR_SIZE[1], ERROR_SIZE[0], 3)
    solution = solve_scene(scene)  # the preset's patches, solver, form factors and meshing
    mask = emitter_ring_mask(solve_scene(scene, 100, meshing="uniform", adaptive=False),
                             ERROR_SIZE)
    error = image_error(solution.image(ERROR_SIZE, supersample=SUPERSAMPLE), reference, mask)
    assert error <= GOAL, f"{error:.4f} with {len(solution.patches)} patches"
