"""The path tracers compared at equal error (issue 13.3): the noise figure behind
``pathtrace_vs_mitsuba_equal_error`` against closed forms."""

from __future__ import annotations

import numpy as np

from shadelab.bench.raytrace import away_from_emitters, variance_per_sample


def test_variance_per_sample_recovers_the_sample_variance():
    """K images of spp samples each with per-sample standard deviation sigma about a mean m:
    the figure is sigma^2 / m^2, whatever spp is (to 5 % with 400 images)."""
    rng = np.random.default_rng(3)
    mean, sigma = 0.5, 0.2
    for spp in (1, 16):
        images = mean + rng.normal(0.0, sigma / np.sqrt(spp), size=(400, 8, 8, 3))
        assert abs(variance_per_sample(images, spp) / (sigma / mean) ** 2 - 1.0) < 0.05


def test_the_mask_leaves_out_the_light_and_its_ring():
    mean = np.full((6, 7, 3), 0.1)
    mean[2, 3] = 20.0
    mask = away_from_emitters(mean)
    assert not mask[1:4, 2:5].any() and mask.sum() == 42 - 9
    images = np.stack([mean, mean, mean + 0.01])
    images[:, 2, 3] += np.array([0.0, 5.0, -5.0])[:, None]     # the light's noise
    only_walls = variance_per_sample(images, 1, mask)
    assert np.isclose(only_walls, (np.var([0, 0, 0.01], ddof=1)) / (0.1 + 0.01 / 3) ** 2)
