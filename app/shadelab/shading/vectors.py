"""Vector helpers of the numpy lighting code (arrays broadcast over leading axes)."""

from __future__ import annotations

import numpy as np

from shadelab.constants import SHADING_EPS as _EPS


def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.sum(a * b, axis=-1)


def normalize(v: np.ndarray) -> np.ndarray:
    """Unit vectors; a zero vector stays zero instead of becoming NaN."""
    length = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.where(length > _EPS, v / np.maximum(length, _EPS), 0.0)
