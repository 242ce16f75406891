"""Image measures the exercises grade with (numpy only): RMSE, luminance and the regions a
*find the pixel* task accepts (computed from the lab's own renders)."""

from __future__ import annotations

import numpy as np

LUMA = np.array([0.2126, 0.7152, 0.0722])   # linear-RGB luminance (Rec. 709)


def rmse(a: np.ndarray, b: np.ndarray) -> float:
    """Root-mean-square difference of two linear RGB images (all channels)."""
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    if a.shape != b.shape:
        raise ValueError(f"images differ in shape: {a.shape} vs {b.shape}")
    return float(np.sqrt(np.mean((a - b) ** 2)))


def luminance(image: np.ndarray) -> np.ndarray:
    return np.asarray(image, np.float64) @ LUMA


def above_fraction(values: np.ndarray, fraction: float) -> np.ndarray:
    """Where ``values`` reach ``fraction`` of their maximum (empty when the maximum is 0)."""
    top = float(values.max(initial=0.0))
    if top <= 1e-9:
        return np.zeros(values.shape, bool)
    return values >= fraction * top


def specular_region(full: np.ndarray, no_specular: np.ndarray, fraction: float) -> np.ndarray:
    """The brightest specular region: where the specular term (the image minus the same image
    with every ks = 0) reaches ``fraction`` of its peak."""
    return above_fraction(luminance(full) - luminance(no_specular), fraction)


def shadow_region(lit: np.ndarray, shadowed: np.ndarray, fraction: float) -> np.ndarray:
    """Where the shadow takes light away: the unshadowed minus the shadowed luminance reaches
    ``fraction`` of its largest value."""
    return above_fraction(luminance(lit) - luminance(shadowed), fraction)


def foreground(image: np.ndarray, background) -> np.ndarray:
    return np.any(np.abs(np.asarray(image, np.float64) - np.asarray(background)) > 1e-6, axis=2)


def mach_region(image: np.ndarray, background, fraction: float) -> np.ndarray:
    """Where the intensity's slope jumps (Mach bands of Gouraud shading): the magnitude of the
    luminance's discrete Laplacian reaches ``fraction`` of its peak, inside the object (pixels
    whose 3x3 neighbourhood is all foreground, so silhouettes do not count)."""
    lum = luminance(image)
    fg = foreground(image, background)
    inner = np.zeros_like(fg)
    inner[1:-1, 1:-1] = np.all([fg[1 + dy:fg.shape[0] - 1 + dy, 1 + dx:fg.shape[1] - 1 + dx]
                                for dy in (-1, 0, 1) for dx in (-1, 0, 1)], axis=0)
    lap = np.zeros_like(lum)
    lap[1:-1, 1:-1] = np.abs(lum[:-2, 1:-1] + lum[2:, 1:-1] + lum[1:-1, :-2] + lum[1:-1, 2:]
                             - 4.0 * lum[1:-1, 1:-1])
    lap[~inner] = 0.0
    return above_fraction(lap, fraction)


def distance_to(region: np.ndarray, pixel: tuple[int, int]) -> float:
    """Chebyshev distance in pixels from (x, y) to the nearest pixel of ``region`` (inf if it
    is empty); 0 inside it."""
    ys, xs = np.nonzero(region)
    if not len(xs):
        return float("inf")
    x, y = pixel
    return float(np.min(np.maximum(np.abs(xs - x), np.abs(ys - y))))


def region_center(region: np.ndarray) -> tuple[int, int] | None:
    """The region's pixel nearest its centroid (x, y)."""
    ys, xs = np.nonzero(region)
    if not len(xs):
        return None
    cx, cy = xs.mean(), ys.mean()
    k = int(np.argmin((xs - cx) ** 2 + (ys - cy) ** 2))
    return int(xs[k]), int(ys[k])


def overlay(image: np.ndarray, region: np.ndarray, color=(1.0, 0.2, 0.1),
            alpha: float = 0.6) -> np.ndarray:
    """The image with ``region`` tinted, for the reveal."""
    out = np.asarray(image, np.float64).copy()
    out[region] = (1 - alpha) * out[region] + alpha * np.asarray(color)
    return out.astype(np.float32)


def difference(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|a - b| scaled so its largest value is 1 (a grey heat map for the reveal)."""
    d = np.abs(np.asarray(a, np.float64) - np.asarray(b, np.float64)).max(axis=2)
    top = float(d.max(initial=0.0))
    d = d / top if top > 0 else d
    return np.repeat(d[..., None], 3, axis=2).astype(np.float32)
