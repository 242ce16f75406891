"""Image error metrics as pbrt-v4's ``imgtool diff`` defines them, on linear images.

All functions take two arrays of the same shape, ``(H, W, 3)`` or ``(N, 3)`` linear
radiance, ``image`` and ``reference``, and an optional boolean ``mask`` over the leading
axes (``(H, W)``) selecting the pixels to compare. Averages run over every selected channel
value. An empty selection gives 0 (nothing to disagree on).

Notes
-----
MAE     = mean |a - b|
MSE     = mean (a - b)^2
RMSE    = sqrt(MSE)
relMSE  = mean (a - b)^2 / (b^2 + eps),  eps = 0.01 (as pbrt's imgtool; keeps black
          reference pixels from dividing by zero)
"""

from __future__ import annotations

import numpy as np

REL_EPS = 1e-2  # relative MSE's guard against b = 0, radiance^2


def _pair(image: np.ndarray, reference: np.ndarray,
          mask: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    a = np.asarray(image, dtype=np.float64)
    b = np.asarray(reference, dtype=np.float64)
    if a.shape != b.shape:
        raise ValueError(f"image shape {a.shape} differs from reference shape {b.shape}")
    if mask is not None:
        m = np.asarray(mask, dtype=bool)
        a, b = a[m], b[m]
    return a, b


def mae(image: np.ndarray, reference: np.ndarray, mask: np.ndarray | None = None) -> float:
    """Mean absolute error."""
    a, b = _pair(image, reference, mask)
    return float(np.mean(np.abs(a - b))) if a.size else 0.0


def mse(image: np.ndarray, reference: np.ndarray, mask: np.ndarray | None = None) -> float:
    """Mean squared error."""
    a, b = _pair(image, reference, mask)
    return float(np.mean((a - b) ** 2)) if a.size else 0.0


def rmse(image: np.ndarray, reference: np.ndarray, mask: np.ndarray | None = None) -> float:
    """Root mean squared error."""
    return float(np.sqrt(mse(image, reference, mask)))


def relmse(image: np.ndarray, reference: np.ndarray, mask: np.ndarray | None = None,
           eps: float = REL_EPS) -> float:
    """Relative mean squared error, mean((a - b)^2 / (b^2 + eps))."""
    a, b = _pair(image, reference, mask)
    return float(np.mean((a - b) ** 2 / (b * b + eps))) if a.size else 0.0


def all_metrics(image: np.ndarray, reference: np.ndarray,
                mask: np.ndarray | None = None) -> dict[str, float]:
    """MAE, RMSE and relative MSE in one dictionary."""
    return {"mae": mae(image, reference, mask), "rmse": rmse(image, reference, mask),
            "relmse": relmse(image, reference, mask)}
