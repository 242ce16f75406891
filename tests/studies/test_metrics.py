"""Error metrics (pbrt imgtool definitions) against closed forms."""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.studies import metrics


def test01_constant_offset_gives_the_offset():
    b = np.full((4, 5, 3), 0.5)
    a = b + 0.1
    assert metrics.mae(a, b) == pytest.approx(0.1, abs=1e-12)
    assert metrics.rmse(a, b) == pytest.approx(0.1, abs=1e-12)
    assert metrics.mse(a, b) == pytest.approx(0.01, abs=1e-12)
    # relMSE = 0.1^2 / (0.5^2 + 0.01) = 0.01 / 0.26
    assert metrics.relmse(a, b) == pytest.approx(0.01 / 0.26, rel=1e-12)


def test02_mixed_errors_closed_form():
    a = np.array([[0.0, 0.0, 0.0], [2.0, 2.0, 2.0]])
    b = np.array([[1.0, 1.0, 1.0], [1.0, 1.0, 1.0]])
    assert metrics.mae(a, b) == pytest.approx(1.0)
    assert metrics.rmse(a, b) == pytest.approx(1.0)
    assert metrics.relmse(a, b) == pytest.approx(1.0 / 1.01)
    c = np.array([[0.0, 0.0, 0.0], [3.0, 3.0, 3.0]])  # errors 1 and 2
    assert metrics.mae(c, b) == pytest.approx(1.5)
    assert metrics.rmse(c, b) == pytest.approx(np.sqrt(2.5))


def test03_relmse_black_reference_uses_eps():
    a = np.full((2, 2, 3), 0.2)
    b = np.zeros((2, 2, 3))
    assert metrics.relmse(a, b) == pytest.approx(0.04 / metrics.REL_EPS)
    assert metrics.relmse(a, b, eps=1.0) == pytest.approx(0.04)


def test04_relmse_is_scale_invariant_for_bright_images():
    rng = np.random.default_rng(1)
    b = rng.uniform(10.0, 20.0, (8, 8, 3))
    a = b * 1.05
    # (0.05 b)^2 / (b^2 + eps) -> 0.0025 when b^2 >> eps
    assert metrics.relmse(a, b) == pytest.approx(0.0025, rel=1e-3)
    assert metrics.relmse(a * 100, b * 100) == pytest.approx(0.0025, rel=1e-5)


def test05_mask_selects_pixels():
    b = np.zeros((2, 2, 3))
    a = np.zeros((2, 2, 3))
    a[0, 0] = 1.0      # outside the mask below
    a[1, 1] = 0.5
    mask = np.array([[False, True], [True, True]])
    assert metrics.mae(a, b, mask) == pytest.approx(0.5 / 3)
    assert metrics.mae(a, b) == pytest.approx(1.5 / 4)
    assert metrics.rmse(a, b, np.zeros((2, 2), bool)) == 0.0


def test06_identical_images_are_zero_and_shapes_must_match():
    a = np.random.default_rng(2).uniform(size=(3, 3, 3))
    assert metrics.all_metrics(a, a) == {"mae": 0.0, "rmse": 0.0, "relmse": 0.0,
                                          "flip": 0.0}
    with pytest.raises(ValueError):
        metrics.mae(a, a[:2])
