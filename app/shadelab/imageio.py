"""Image output and the CLI arguments every renderer shares (PRESET, -o, --size, --set, --npy)."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from PIL import Image

from shadelab.errors import ShadeLabError
from shadelab.shading.conventions import to_srgb8

MAX_SIZE = 16384  # pixels per side


def parse_size(text: str) -> tuple[int, int]:
    """``WxH`` (or a single ``N`` for a square) -> (width, height), each in [1, 16384]."""
    parts = text.lower().split("x")
    try:
        if len(parts) == 1:
            w = h = int(parts[0])
        elif len(parts) == 2:
            w, h = int(parts[0]), int(parts[1])
        else:
            raise ValueError
    except ValueError:
        raise ShadeLabError(f"--size '{text}': expected WxH, e.g. 800x600") from None
    if not (1 <= w <= MAX_SIZE and 1 <= h <= MAX_SIZE):
        raise ShadeLabError(f"--size '{text}': expected each side in [1, {MAX_SIZE}]")
    return w, h


def check_writable(path: str | None, flag: str) -> None:
    """Fail before any work if ``path`` cannot be written (nothing is half-written later)."""
    if not path:
        return
    target = Path(path)
    folder = target.resolve().parent
    if not folder.is_dir():
        raise ShadeLabError(f"{flag} '{path}': folder '{folder}' does not exist")
    if target.is_dir():
        raise ShadeLabError(f"{flag} '{path}': is a folder, expected a file name")
    existed = target.exists()
    try:  # append mode: an existing file is left as it is
        with open(target, "ab"):
            pass
    except OSError as exc:
        raise ShadeLabError(f"{flag} '{path}': not writable ({exc.strerror})") from None
    if not existed:
        target.unlink(missing_ok=True)


def write_png(path: str, linear: np.ndarray, exposure: float = 1.0) -> None:
    """Write linear RGB (H, W, 3) as an sRGB PNG."""
    try:
        Image.fromarray(to_srgb8(linear, exposure)).save(path)
    except (OSError, ValueError) as exc:
        raise ShadeLabError(f"-o '{path}': cannot write image ({exc})") from None


def write_npy(path: str, linear: np.ndarray) -> None:
    """Write float32 linear radiance (H, W, 3), row 0 at the top."""
    try:
        np.save(path, np.ascontiguousarray(linear, dtype=np.float32))
    except OSError as exc:
        raise ShadeLabError(f"--npy '{path}': cannot write array ({exc.strerror})") from None


def add_scene_arguments(parser: argparse.ArgumentParser, default_size: str = "800x600") -> None:
    parser.add_argument("preset", metavar="PRESET", help="preset name from presets/ or a path")
    parser.add_argument("-o", "--output", required=True, metavar="OUT.png", help="PNG to write")
    parser.add_argument("--size", default=default_size, metavar="WxH", help="image size")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="override a preset value, e.g. materials.white.kd=0.5")
    parser.add_argument("--npy", metavar="OUT.npy", help="also write float32 linear radiance")


def save_outputs(args: argparse.Namespace, image: np.ndarray, exposure: float = 1.0) -> None:
    write_png(args.output, image, exposure)
    if args.npy:
        write_npy(args.npy, image)


def check_outputs(args: argparse.Namespace) -> None:
    check_writable(args.output, "-o")
    check_writable(args.npy, "--npy")
