"""Radiosity against the reference path tracer on the Cornell box (the same scene, units and
camera: radiance images aligned pixel for pixel).

Error measure (:func:`shadelab.bench.radiosity.image_error`): relative L1 over the pixels away
from the light (the light and a one-pixel ring around it are excluded: both methods show its
Le by definition, and its edge pixels, 100 times brighter than the walls, measure only how
each samples the light's outline). Radiosity is drawn with 16 x 16 sub-pixels per pixel, the
box filter the path tracer's jittered samples make.

Bound: 9 %. Measured 4.7 % and 5.0 % (path-tracer seeds 0 and 1) at 24 x 24 pixels, 512
samples per pixel and 400 uniform patches (5.6 % and 5.8 % with the former 4 x 4 sub-pixels,
whose coverage error at silhouettes and room edges was part of the figure). About 3 % of
it is the reference's own noise (two 512-spp images differ by ~4 %); the rest is
radiosity's discretization: patches ~69 mm wide interpolated across shadow edges and room
corners, with a bias of -1.2 % to -1.3 % in mean radiance that shrinks with more patches.
Wrong units (a factor pi: 200 %), missing occlusion or an image one pixel off (> 20 %) each
exceed the bound (the last is checked).
"""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.bench.radiosity import emitter_ring_mask, image_error, radiosity_image
from shadelab.scene.preset import load_preset

BOUND = 0.09
SIZE = (24, 24)


@pytest.fixture(scope="module")
def images():
    from shadelab.raytrace import pathtrace

    scene = load_preset("cornell")
    reference = pathtrace.render_pathtraced(scene, SIZE, 512, seed=0)
    solution, image = radiosity_image(scene, SIZE, 400)
    return reference, image, emitter_ring_mask(solution, SIZE)


def test01_cornell_radiosity_matches_the_path_tracer(images):
    reference, image, mask = images
    assert reference.shape == image.shape == (24, 24, 3)
    assert 0.9 < mask.mean() < 0.99  # the light and its ring only
    assert image_error(image, reference, mask) < BOUND


def test02_energy_balance(images):
    """Mean radiance away from the light: within 4 % per channel (measured -1.2 %..-1.3 %)."""
    reference, image, mask = images
    ratio = image[mask].mean(axis=0) / reference[mask].mean(axis=0)
    np.testing.assert_allclose(ratio, 1.0, atol=0.04)


def test03_the_bound_catches_a_one_pixel_shift(images):
    reference, image, mask = images
    shifted = np.roll(image, 1, axis=1)
    assert image_error(shifted, reference, mask) > BOUND
