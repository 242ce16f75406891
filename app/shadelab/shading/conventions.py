"""Conventions shared by the numpy reference, the GLSL include and the CPU renderers.

- Directions point away from the surface: ``to_light`` (L) and ``to_eye`` (V).
  A light's ``direction`` field is the way its photons travel, so L = -direction.
- Normals are unit length, world space, and face the viewer side being shaded.
- Colors are linear RGB; PNG files are sRGB-encoded at output only (:func:`to_srgb8`).
- Dot products are clamped at 0; pow(0, 0) is defined as 0 outside the lobe, 1 inside.
"""

from __future__ import annotations

import numpy as np

# The sRGB transfer function (IEC 61966-2-1); shaders/include/color.glsl gets these values as
# generated #defines (glsl_header), so the shader and the PNG writer encode alike.
SRGB_LINEAR_MAX = 0.0031308  # linear values up to here are scaled, above: a power law
SRGB_SLOPE = 12.92  # the linear segment's slope
SRGB_SCALE = 1.055  # the power segment: SCALE * c^(1 / GAMMA) - OFFSET
SRGB_OFFSET = 0.055
SRGB_GAMMA = 2.4
# The display pass's encoding (shaders/include/color.glsl to_srgb_display): the power segment
# as a degree-8 polynomial in t = c^(1/4) (two square roots, eight multiply-adds per channel;
# llvmpipe's pow is a log2 and an exp2 approximation, ~4 ms of a 1024x672 frame). Coefficients
# in float32, lowest order first: a least-squares Chebyshev fit of SCALE t^(4/GAMMA) - OFFSET on
# [SRGB_LINEAR_MAX^(1/4), 1], within 7e-5 of an 8-bit code everywhere (tests/shaders/
# test_display_encoding.py refits it); a code differs from to_srgb8's only where the exact
# value lies that close to a rounding threshold (1.5e-5 of values, by 1).
SRGB_POLY = (-0.05783136934041977, 0.11321315169334412, 1.5348799228668213, -1.4410881996154785,
             1.8761974573135376, -1.8614805936813354, 1.2348675727844238, -0.4821125566959381,
             0.0833546593785286)
# The difference heat map: black -> blue -> green -> yellow -> red as t goes 0 -> 1
HEAT_STOPS = ((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.0, 1.0, 0.0), (1.0, 1.0, 0.0), (1.0, 0.0, 0.0))
HEAT_EPS = 1e-12  # guard of the heat map's full-scale difference


def linear_to_srgb(linear) -> np.ndarray:
    """The sRGB encoding of linear values (negatives to 0; above 1 the power law goes on, so
    :func:`srgb_to_linear` undoes it)."""
    c = np.maximum(np.asarray(linear, dtype=np.float64), 0.0)
    return np.where(c <= SRGB_LINEAR_MAX, SRGB_SLOPE * c,
                    SRGB_SCALE * np.power(c, 1.0 / SRGB_GAMMA) - SRGB_OFFSET)


def srgb_to_linear(srgb) -> np.ndarray:
    """The linear values of sRGB-encoded ones (the inverse of :func:`linear_to_srgb`)."""
    s = np.maximum(np.asarray(srgb, dtype=np.float64), 0.0)
    return np.where(s <= SRGB_SLOPE * SRGB_LINEAR_MAX, s / SRGB_SLOPE,
                    np.power((s + SRGB_OFFSET) / SRGB_SCALE, SRGB_GAMMA))


def to_srgb8(linear: np.ndarray, exposure: float = 1.0) -> np.ndarray:
    """Linear RGB (H, W, 3) -> sRGB uint8, clipped to [0, 1] after exposure."""
    c = np.clip(np.nan_to_num(linear * exposure, nan=0.0, posinf=1.0), 0.0, 1.0)
    srgb = np.where(c <= SRGB_LINEAR_MAX, SRGB_SLOPE * c,
                    SRGB_SCALE * np.power(c, 1.0 / SRGB_GAMMA) - SRGB_OFFSET)
    return np.round(srgb * 255.0).astype(np.uint8)


def display_srgb8(linear: np.ndarray, exposure: float = 1.0) -> np.ndarray:
    """:func:`to_srgb8` as the display pass computes it (color.glsl ``to_srgb_display``): in
    float32, the power segment by :data:`SRGB_POLY` in c^(1/4), rounded as a unorm8 write."""
    x = np.asarray(linear, dtype=np.float32) * np.float32(exposure)
    c = np.clip(np.nan_to_num(x, nan=0.0, posinf=1.0), 0.0, 1.0).astype(np.float32)
    t = np.sqrt(np.sqrt(c))
    power = np.zeros_like(t)
    for coefficient in np.float32(SRGB_POLY)[::-1]:
        power = power * t + coefficient
    srgb = np.where(c <= np.float32(SRGB_LINEAR_MAX), np.float32(SRGB_SLOPE) * c, power)
    return np.floor(srgb * np.float32(255.0) + np.float32(0.5)).astype(np.uint8)


def heat_map(a: np.ndarray, b: np.ndarray, scale: float) -> np.ndarray:
    """(H, W, 3) uint8: max-channel |a - b| / scale through black-blue-green-yellow-red."""
    t = np.clip(np.abs(a - b).max(axis=-1) / max(scale, HEAT_EPS), 0.0, 1.0) * 4.0
    stops = np.array(HEAT_STOPS, np.float64)
    i = np.minimum(t.astype(int), 3)
    f = (t - i)[..., None]
    return np.round((stops[i] * (1 - f) + stops[i + 1] * f) * 255).astype(np.uint8)


def glsl_header() -> str:
    """The sRGB and heat-map constants as ``#define`` lines (for shaders/include/color.glsl)."""
    defines = {"SRGB_LINEAR_MAX": SRGB_LINEAR_MAX, "SRGB_SLOPE": SRGB_SLOPE,
               "SRGB_SCALE": SRGB_SCALE, "SRGB_OFFSET": SRGB_OFFSET, "SRGB_GAMMA": SRGB_GAMMA,
               "HEAT_EPS": HEAT_EPS}
    lines = [f"#define {name} {value!r}" for name, value in defines.items()]
    lines += [f"#define HEAT_STOP_{k} vec3({', '.join(map(repr, stop))})"
              for k, stop in enumerate(HEAT_STOPS)]
    lines += [f"#define SRGB_POLY_{k} {value!r}" for k, value in enumerate(SRGB_POLY)]
    return "// Generated from shadelab/shading/conventions.py.\n" + "\n".join(lines) + "\n"
