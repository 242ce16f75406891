"""The display pass's sRGB encoding without pow (issue 25): conventions.SRGB_POLY, a polynomial
in c^(1/4), mirrored by color.glsl's to_srgb_display. It must give to_srgb8's codes but where
the exact value lies within float rounding of a rounding threshold."""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.shading.conventions import (
    SRGB_GAMMA,
    SRGB_LINEAR_MAX,
    SRGB_OFFSET,
    SRGB_POLY,
    SRGB_SCALE,
    display_srgb8,
    to_srgb8,
)

# a code may differ from to_srgb8's by 1, for at most this share of values
MISMATCH_SHARE = 1e-4


def _power_segment(t: np.ndarray) -> np.ndarray:
    """The exact sRGB power segment in t = c^(1/4): SCALE t^(4/GAMMA) - OFFSET."""
    return SRGB_SCALE * t ** (4.0 / SRGB_GAMMA) - SRGB_OFFSET


def _values(rng) -> np.ndarray:
    """A fine ramp on [0, 1] (both ends) and random values, as (N, 3)."""
    ramp = np.linspace(0.0, 1.0, 600_000, dtype=np.float32)
    return np.concatenate([ramp, rng.random(600_000, dtype=np.float32)]).reshape(-1, 3)


def test_the_polynomial_is_the_power_segment_within_1e4_of_a_code():
    t = np.linspace(SRGB_LINEAR_MAX ** 0.25, 1.0, 200_001)
    approx = np.polynomial.polynomial.polyval(t, SRGB_POLY)
    assert np.abs(approx - _power_segment(t)).max() * 255.0 < 1e-4


def test_the_coefficients_are_the_documented_fit():
    """A least-squares Chebyshev fit of degree 8 on [SRGB_LINEAR_MAX^(1/4), 1], in float32."""
    t = np.linspace(SRGB_LINEAR_MAX ** 0.25, 1.0, 400_001)
    fit = np.polynomial.chebyshev.Chebyshev.fit(t, _power_segment(t), 8)
    coefficients = fit.convert(kind=np.polynomial.Polynomial).coef
    np.testing.assert_allclose(SRGB_POLY, coefficients.astype(np.float32), rtol=1e-5,
                               atol=1e-6)


def test_the_numpy_mirror_gives_to_srgb8s_codes(np_rng):
    values = _values(np_rng)
    for exposure in (1.0, 0.6, 3.0):
        ours = display_srgb8(values, exposure).astype(int)
        exact = to_srgb8(values.astype(np.float64), exposure).astype(int)
        assert np.abs(ours - exact).max() <= 1
        assert (ours != exact).mean() < MISMATCH_SHARE
    edges = np.array([[0.0, SRGB_LINEAR_MAX, 1.0], [-1.0, 2.0, np.nan]], np.float32)
    np.testing.assert_array_equal(display_srgb8(edges), [[0, 10, 255], [0, 255, 0]])


@pytest.mark.gl
def test_the_display_pass_gives_to_srgb8s_codes(gl_ctx, np_rng):
    from shadelab.ui.viewport import Viewport

    vp = Viewport(gl_ctx)
    try:
        size = (800, 500)
        values = _values(np_rng)[: size[0] * size[1]]
        image = np.concatenate([values, np.ones((len(values), 1), np.float32)], axis=1)
        pane = vp.pane("main", size)
        pane.target.color.write(image.astype("f4").tobytes())
        for exposure in (1.0, 0.6):
            vp.present(pane, exposure)
            shown = vp.read_display("main")[::-1].reshape(-1, 3).astype(int)  # rows as written
            exact = to_srgb8(values.astype(np.float64), exposure).astype(int)
            assert np.abs(shown - exact).max() <= 1
            assert (shown != exact).mean() < MISMATCH_SHARE
    finally:
        vp.release()
