"""Golden-image comparison with stated thresholds; failures write img/ref/diff to tests/_output.

Thresholds (sRGB 8-bit, images blessed on Mesa llvmpipe): at most 0.1 % of pixels may differ
by more than 2/255 in any channel, and the RMSE must stay below 1/255.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image

GOLDEN_DIR = Path(__file__).resolve().parent / "golden"
OUTPUT_DIR = Path(__file__).resolve().parent / "_output"
PIXEL_TOLERANCE = 2          # 8-bit levels
MAX_DIFFERING_SHARE = 0.001  # share of pixels allowed above PIXEL_TOLERANCE
MAX_RMSE = 1.0               # 8-bit levels


def compare_golden(name: str, image: np.ndarray, update: bool) -> None:
    """``image`` is sRGB uint8 (H, W, 3)."""
    path = GOLDEN_DIR / f"{name}.png"
    if update:
        GOLDEN_DIR.mkdir(exist_ok=True)
        Image.fromarray(image).save(path)
        return
    assert path.is_file(), f"no golden image {path.name}: run pytest --update-golden"
    reference = np.asarray(Image.open(path).convert("RGB"))
    assert reference.shape == image.shape, f"{name}: size {image.shape} != {reference.shape}"
    diff = np.abs(image.astype(np.int16) - reference.astype(np.int16))
    share = float(np.mean(diff.max(axis=2) > PIXEL_TOLERANCE))
    rmse = float(np.sqrt(np.mean(diff.astype(np.float64) ** 2)))
    if share > MAX_DIFFERING_SHARE or rmse > MAX_RMSE:
        OUTPUT_DIR.mkdir(exist_ok=True)
        Image.fromarray(image).save(OUTPUT_DIR / f"{name}_img.png")
        Image.fromarray(reference).save(OUTPUT_DIR / f"{name}_ref.png")
        magnified = np.clip(diff * 16, 0, 255).astype(np.uint8)
        Image.fromarray(magnified).save(OUTPUT_DIR / f"{name}_diff.png")
        raise AssertionError(f"{name}: {share:.2%} of pixels differ by > {PIXEL_TOLERANCE}/255 "
                             f"(allowed {MAX_DIFFERING_SHARE:.2%}), RMSE {rmse:.2f}/255 "
                             f"(allowed {MAX_RMSE}); see tests/_output/{name}_*.png")
