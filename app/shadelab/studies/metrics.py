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
FLIP    = mean of NVIDIA's LDR FLIP error map (the ``flip-evaluator`` package, as pbrt's
          ``imgtool diff --metric FLIP``) over the selected pixels, in [0, 1]: 0 for identical
          images. It compares what the viewer shows: both images are scaled by ``exposure`` and
          clipped to [0, 1] (linear), 67 pixels per degree. Only for (H, W, 3) images.
"""

from __future__ import annotations

import numpy as np

REL_EPS = 1e-2  # relative MSE's guard against b = 0, radiance^2
FLIP_MIN_SIDE = 2  # flip-evaluator needs at least a 2x2 image


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


def flip_map(image: np.ndarray, reference: np.ndarray, exposure: float = 1.0) -> np.ndarray:
    """NVIDIA FLIP's per-pixel LDR error (H, W) in [0, 1] of two linear (H, W, 3) images."""
    import flip_evaluator

    a = np.asarray(image, dtype=np.float64)
    b = np.asarray(reference, dtype=np.float64)
    if a.shape != b.shape:
        raise ValueError(f"image shape {a.shape} differs from reference shape {b.shape}")
    if a.ndim != 3 or a.shape[2] != 3 or min(a.shape[:2]) < FLIP_MIN_SIDE:
        raise ValueError(f"FLIP needs (H, W, 3) images of at least {FLIP_MIN_SIDE}x"
                         f"{FLIP_MIN_SIDE} pixels, got {a.shape}")

    def ldr(x: np.ndarray) -> np.ndarray:
        return np.clip(np.nan_to_num(x * exposure, nan=0.0, posinf=1.0), 0.0, 1.0)

    error, _, _ = flip_evaluator.evaluate(ldr(b).astype(np.float32), ldr(a).astype(np.float32),
                                          "LDR", inputsRGB=False, applyMagma=False,
                                          computeMeanError=False)
    return np.asarray(error, dtype=np.float64).reshape(a.shape[:2])


def flip(image: np.ndarray, reference: np.ndarray, mask: np.ndarray | None = None,
         exposure: float = 1.0) -> float:
    """Mean FLIP error over the selected pixels (0 = identical, 1 = maximal)."""
    error = flip_map(image, reference, exposure)
    if mask is not None:
        error = error[np.asarray(mask, dtype=bool)]
    return float(np.mean(error)) if error.size else 0.0


def all_metrics(image: np.ndarray, reference: np.ndarray,
                mask: np.ndarray | None = None) -> dict[str, float]:
    """MAE, RMSE, relative MSE and (for (H, W, 3) images) FLIP in one dictionary."""
    out = {"mae": mae(image, reference, mask), "rmse": rmse(image, reference, mask),
           "relmse": relmse(image, reference, mask)}
    shape = np.shape(image)
    if len(shape) == 3 and shape[2] == 3 and min(shape[:2]) >= FLIP_MIN_SIDE:
        out["flip"] = flip(image, reference, mask)
    return out
