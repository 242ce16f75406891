"""Conventions shared by the numpy reference, the GLSL include and the CPU renderers.

- Directions point away from the surface: ``to_light`` (L) and ``to_eye`` (V).
  A light's ``direction`` field is the way its photons travel, so L = -direction.
- Normals are unit length, world space, and face the viewer side being shaded.
- Colors are linear RGB; PNG files are sRGB-encoded at output only (:func:`to_srgb8`).
- Dot products are clamped at 0; pow(0, 0) is defined as 0 outside the lobe, 1 inside.
"""

from __future__ import annotations

import numpy as np


def to_srgb8(linear: np.ndarray, exposure: float = 1.0) -> np.ndarray:
    """Linear RGB (H, W, 3) -> sRGB uint8, clipped to [0, 1] after exposure."""
    c = np.clip(np.nan_to_num(linear * exposure, nan=0.0, posinf=1.0), 0.0, 1.0)
    srgb = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)
    return np.round(srgb * 255.0).astype(np.uint8)
