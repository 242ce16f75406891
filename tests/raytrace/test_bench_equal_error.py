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


def test_the_per_sampler_rows_carry_speed_noise_and_the_ratio():
    """``by_sampler``: one row per Mitsuba sampler with both samples/s and noise figures and
    the equal-error ratio the bench paired (their time to a given error over ours)."""
    from shadelab.bench.raytrace import by_sampler

    ours = {"sobol": {"samples_per_s": 3e5, "variance_per_sample": 0.30}}
    theirs = {"ldsampler": {"samples_per_s": 5e5, "variance_per_sample": 0.31},
              "independent": {"samples_per_s": 6e5, "variance_per_sample": 0.57}}
    ratios = {f"sobol_vs_{name}": {"equal_error_ratio": (3e5 / t["samples_per_s"])
                                   * t["variance_per_sample"] / 0.30,
                                   "equal_error_ratio_cpu": 1.0}
              for name, t in theirs.items()}
    rows = by_sampler({"ours": ours, "mitsuba": theirs, "ratios": ratios})
    assert set(rows) == {"ldsampler", "independent"}
    row = rows["ldsampler"]
    assert row["ours_samples_per_s"] == 3e5 and row["mitsuba_noise_per_sample"] == 0.31
    assert np.isclose(row["equal_error_ratio"], 0.6 * 0.31 / 0.30)
    assert np.isclose(rows["independent"]["equal_error_ratio"], 0.5 * 0.57 / 0.30)
