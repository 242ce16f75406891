"""NVIDIA FLIP (flip-evaluator) beside MAE / RMSE / relMSE: closed cases and the studies' rows."""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.studies import metrics


def test_identical_images_have_zero_flip():
    a = np.random.default_rng(7).random((48, 40, 3))
    assert metrics.flip(a, a.copy()) == 0.0
    assert np.all(metrics.flip_map(a, a) == 0.0)


def test_black_against_white_is_near_the_maximum():
    value = metrics.flip(np.zeros((16, 16, 3)), np.ones((16, 16, 3)))
    assert 0.9 < value <= 1.0


def test_a_larger_change_scores_higher_and_stays_in_range():
    ref = np.full((32, 32, 3), 0.5)
    small = metrics.flip(ref + 0.02, ref)
    large = metrics.flip(ref + 0.2, ref)
    assert 0.0 < small < large < 1.0


def test_mask_and_exposure():
    ref = np.full((64, 64, 3), 0.4)
    img = ref.copy()
    img[:, :32] = 0.8
    far = np.zeros((64, 64), dtype=bool)
    far[:, 48:] = True  # 16 pixels from the edge: FLIP's filters do not reach there
    assert metrics.flip(img, ref, far) < 1e-3
    assert metrics.flip(img, ref, ~far) > 0.1
    assert metrics.flip(img, ref, np.zeros((64, 64), dtype=bool)) == 0.0
    # beyond 1 after exposure both are white: what the viewer shows does not differ
    assert metrics.flip(np.full((8, 8, 3), 2.0), np.full((8, 8, 3), 3.0)) == 0.0
    assert metrics.flip(np.full((8, 8, 3), 2.0), np.full((8, 8, 3), 3.0), exposure=0.25) > 0.0


def test_all_metrics_reports_flip_for_images_only():
    a = np.random.default_rng(1).random((8, 8, 3))
    assert set(metrics.all_metrics(a, a * 0.5)) == {"mae", "rmse", "relmse", "flip"}
    assert set(metrics.all_metrics(a.reshape(-1, 3), a.reshape(-1, 3))) == {"mae", "rmse",
                                                                            "relmse"}
    with pytest.raises(ValueError, match="FLIP needs"):
        metrics.flip(a.reshape(-1, 3), a.reshape(-1, 3))


def test_the_studies_rows_carry_flip():
    from shadelab.studies import radiosity_study, raytrace_study, shading_study

    for module in (raytrace_study, radiosity_study, shading_study):
        assert module.COLUMNS[-1] == "flip"
