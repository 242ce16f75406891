"""Golden-image comparison with stated thresholds; failures write img/ref/diff to tests/_output.

The machinery lives in :mod:`shadelab.testing` (so courses use the same); ShadeLab's own
goldens use its ``golden`` threshold (sRGB 8-bit, images blessed on Mesa llvmpipe): at most
0.1 % of pixels may differ by more than 2/255 in any channel, and the RMSE must stay below 1/255.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from shadelab.testing import THRESHOLDS, assert_images_close

GOLDEN_DIR = Path(__file__).resolve().parent / "golden"
OUTPUT_DIR = Path(__file__).resolve().parent / "_output"
GOLDEN = THRESHOLDS["golden"]
PIXEL_TOLERANCE = GOLDEN.pixel          # 8-bit levels
MAX_DIFFERING_SHARE = GOLDEN.max_share  # share of pixels allowed above PIXEL_TOLERANCE
MAX_RMSE = GOLDEN.max_rmse              # 8-bit levels


def compare_golden(name: str, image: np.ndarray, update: bool) -> None:
    """``image`` is sRGB uint8 (H, W, 3); ``update`` rewrites golden/<name>.png."""
    assert_images_close(image, GOLDEN_DIR / f"{name}.png", "golden", name=name,
                        output_dir=OUTPUT_DIR, regenerate=update or None)
