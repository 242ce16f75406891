"""Surface detail on the CPU: texture-mapped Od and bump-mapped normals, in numpy.

The term-by-term twin of ``shaders/include/surface.glsl`` (used by the raster's ``*_tex``
programs), so the ray tracers shade textured materials as the raster does:

- Od(u, v) = Od * image(s u, s v) (linear RGB), or a checker of Od and ``texture_color2`` with
  s x s cells over [0, 1] uv; s = ``texture_scale``;
- bumps (Blinn 1978): N' = normalize(N - k (H_x T + H_y B)), H = 0.5 + 0.5 sin(2 pi x)
  sin(2 pi y) for ``"bumps"`` or a height image (central differences one texel apart), over
  pattern coordinates x = s u, y = s v; k = ``bump_scale``; T, B the unit directions of
  increasing u and v, orthogonalized against N;
- image lookups as the GL sampler of :mod:`shadelab.raster.textures`: GL_REPEAT wrap,
  bilinear (GL_LINEAR, level 0), texel centres at (i + 0.5) / W, row 0 at v = 0.

Also the image loading (sRGB decoded to linear; height maps as stored), which the GL side
imports from here. No GL: pure numpy and PIL.
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:   # pillow is imported where an image is read: ~20 ms of the viewer's start
    from PIL import Image

from shadelab.errors import ShadeLabError
from shadelab.paths import file_problem
from shadelab.scene.model import Material

TEXTURE_MODES = {"": 0, "checker": 1}  # anything else: an image file (mode 2)
BUMP_MODES = {"": 0, "bumps": 1}


def has_surface_detail(material: Material) -> bool:
    return bool(material.texture) or bool(material.bump)


MAX_TEXTURE_PIXELS = 8192 * 8192  # 64 Mpixels: 768 MiB as float32 RGB, a GL texture's limit
LIMIT_ENV = "SHADELAB_MAX_TEXTURE_PIXELS"


def _resolve(path: str, base_dir: str, key: str) -> Path:
    full = Path(path) if Path(path).is_absolute() else Path(base_dir) / path
    problem = file_problem(full)
    if problem:
        raise ShadeLabError(f"{key}: image file '{full}' {problem}")
    return full


def texture_limit() -> int:
    """The largest image (pixels) a texture may be; ``SHADELAB_MAX_TEXTURE_PIXELS`` raises it."""
    text = os.environ.get(LIMIT_ENV, "")
    if not text:
        return MAX_TEXTURE_PIXELS
    if not (text.isascii() and text.isdigit()) or int(text) < 1:
        raise ShadeLabError(f"{LIMIT_ENV}={text!r}: expected a pixel count >= 1")
    return int(text)


def check_image_size(image: Image.Image, full: Path, key: str) -> None:
    """Refuse an image too large to decode (a decompression bomb), from its header alone."""
    w, h = image.size
    limit = texture_limit()
    if w * h > limit:
        raise ShadeLabError(f"{key}: '{full.name}' is {w}x{h} = {w * h / 1e6:.0f} Mpixels, "
                            f"over the texture limit of {limit / 1e6:.0f} Mpixels "
                            f"(~{w * h * 12 / 2**30:.1f} GiB as float RGB); scale it down, "
                            f"or set {LIMIT_ENV} to allow more")


def srgb_to_linear(c: np.ndarray) -> np.ndarray:
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def _open_checked(full: Path, key: str) -> Image.Image:
    """Image.open (the header only) with our size check in place of PIL's bomb check, whose
    error names neither the limit nor how to raise it."""
    from PIL import Image

    saved = Image.MAX_IMAGE_PIXELS
    Image.MAX_IMAGE_PIXELS = None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            image = Image.open(full)
    finally:
        Image.MAX_IMAGE_PIXELS = saved
    try:
        check_image_size(image, full, key)
    except ShadeLabError:
        image.close()
        raise
    return image


def check_image_file(path: str, base_dir: str, key: str) -> tuple[int, int]:
    """Read only the header: the file is an image within the size limit; its (w, h)."""
    from PIL import UnidentifiedImageError

    full = _resolve(path, base_dir, key)
    try:
        with _open_checked(full, key) as image:
            return image.size
    except (UnidentifiedImageError, OSError, ValueError, SyntaxError) as exc:
        # ValueError: a text chunk past Pillow's decompression limit (a zTXt bomb) and other
        # malformed chunks; SyntaxError: a broken header
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ShadeLabError(f"{key}: '{full.name}' could not be read as an image "
                            f"({reason})") from None


def load_image(path: str, base_dir: str, key: str, height: bool = False) -> np.ndarray:
    """(H, W, 3) linear RGB or (H, W) height in [0, 1], float32, row 0 at the BOTTOM (GL's v)."""
    from PIL import UnidentifiedImageError

    full = _resolve(path, base_dir, key)
    try:
        with _open_checked(full, key) as image:
            pixels = np.asarray(image.convert("L" if height else "RGB"), dtype=np.float32)
    except (UnidentifiedImageError, OSError, ValueError, SyntaxError) as exc:
        # ValueError: a text chunk past Pillow's decompression limit (a zTXt bomb) and other
        # malformed chunks; SyntaxError: a broken header
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ShadeLabError(f"{key}: '{full.name}' could not be read as an image "
                            f"({reason})") from None
    pixels = pixels[::-1] / 255.0
    if not height:
        pixels = srgb_to_linear(pixels)
    return np.ascontiguousarray(pixels, dtype=np.float32)


# ------------------------------------------------------------------ surface.glsl in numpy

TAU = 2.0 * np.pi


def sample_linear_repeat(image: np.ndarray, p: np.ndarray) -> np.ndarray:
    """``textureLod(image, p, 0)`` with GL_REPEAT and GL_LINEAR: (N, C) or (N,) for (H, W)."""
    h, w = image.shape[:2]
    x = p[:, 0] * w - 0.5
    y = p[:, 1] * h - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = x - x0, y - y0
    i0 = np.mod(x0.astype(np.int64), w)
    j0 = np.mod(y0.astype(np.int64), h)
    i1, j1 = (i0 + 1) % w, (j0 + 1) % h
    img = np.asarray(image, dtype=np.float64)
    if img.ndim == 3:
        fx, fy = fx[:, None], fy[:, None]
    return ((1.0 - fy) * ((1.0 - fx) * img[j0, i0] + fx * img[j0, i1])
            + fy * ((1.0 - fx) * img[j1, i0] + fx * img[j1, i1]))


def checker(uv: np.ndarray, scale: float, od, color2) -> np.ndarray:
    """(N, 3): Od where floor(s u) + floor(s v) is even, ``color2`` where odd."""
    cell = np.floor(uv * scale)
    even = np.mod(cell[:, 0] + cell[:, 1], 2.0) < 0.5
    return np.where(even[:, None], np.asarray(od, np.float64)[None],
                    np.asarray(color2, np.float64)[None])


def height_gradient_bumps(uv: np.ndarray, scale: float) -> np.ndarray:
    """(N, 2) (dH/dx, dH/dy) of H = 0.5 + 0.5 sin(2 pi x) sin(2 pi y), pattern coordinates."""
    p = uv * scale
    sx, cx = np.sin(TAU * p[:, 0]), np.cos(TAU * p[:, 0])
    sy, cy = np.sin(TAU * p[:, 1]), np.cos(TAU * p[:, 1])
    return 0.5 * TAU * np.stack([cx * sy, sx * cy], axis=1)


def height_gradient_image(uv: np.ndarray, scale: float, height: np.ndarray) -> np.ndarray:
    """(N, 2) central differences of a height image one texel apart, per pattern unit."""
    p = uv * scale
    h, w = height.shape[:2]
    tx, ty = 1.0 / w, 1.0 / h
    dx, dy = np.array([tx, 0.0]), np.array([0.0, ty])
    hx = sample_linear_repeat(height, p + dx) - sample_linear_repeat(height, p - dx)
    hy = sample_linear_repeat(height, p + dy) - sample_linear_repeat(height, p - dy)
    return np.stack([hx / (2.0 * tx), hy / (2.0 * ty)], axis=1)


def _unit_or_zero(v: np.ndarray) -> np.ndarray:
    length = np.linalg.norm(v, axis=1, keepdims=True)
    return np.where(length > 1e-20, v / np.maximum(length, 1e-300), 0.0)


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("ij,ij->i", a, b)[:, None]


def bump_normal(n: np.ndarray, dpdu: np.ndarray, dpdv: np.ndarray, gradient: np.ndarray,
                bump_scale: float) -> np.ndarray:
    """(N, 3) normalize(N - k (H_x T + H_y B)), T and B Gram-Schmidt against N (zero if
    degenerate)."""
    t = _unit_or_zero(dpdu - n * _dot(n, dpdu))
    b = _unit_or_zero(dpdv - n * _dot(n, dpdv) - t * _dot(t, dpdv))
    bumped = n - bump_scale * (gradient[:, :1] * t + gradient[:, 1:] * b)
    return bumped / np.linalg.norm(bumped, axis=1, keepdims=True)


def triangle_tangents(corners: np.ndarray, uvs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """dP/du, dP/dv (F, 3) of triangles (F, 3, 3) with corner uvs (F, 3, 2); zero where the
    uv triangle is degenerate."""
    e1, e2 = corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    d1, d2 = uvs[:, 1] - uvs[:, 0], uvs[:, 2] - uvs[:, 0]
    det = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    ok = np.abs(det) >= 1e-20
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)[:, None]
    dpdu = (e1 * d2[:, 1:] - e2 * d1[:, 1:]) * inv
    dpdv = (e2 * d1[:, :1] - e1 * d2[:, :1]) * inv
    return dpdu, dpdv


class MaterialDetail:
    """One material's texture and bump, images loaded once (relative to ``base_dir``)."""

    def __init__(self, name: str, material: Material, base_dir: str = "."):
        self.material = material
        self.texture_mode = TEXTURE_MODES.get(material.texture, 2)
        self.bump_mode = BUMP_MODES.get(material.bump, 2)
        self.scale = float(material.texture_scale)
        self.image = (load_image(material.texture, base_dir, f"materials.{name}.texture")
                      if self.texture_mode == 2 else None)
        self.height = (load_image(material.bump, base_dir, f"materials.{name}.bump", True)
                       if self.bump_mode == 2 else None)

    def od(self, uv: np.ndarray) -> np.ndarray:
        """(N, 3) ``surface_od(uv)``."""
        od = np.asarray(self.material.Od, np.float64)
        if self.texture_mode == 1:
            return checker(uv, self.scale, od, self.material.texture_color2)
        if self.texture_mode == 2:
            return od[None] * sample_linear_repeat(self.image, uv * self.scale)
        return np.broadcast_to(od, (len(uv), 3)).copy()

    def normal(self, n: np.ndarray, dpdu: np.ndarray, dpdv: np.ndarray,
               uv: np.ndarray) -> np.ndarray:
        """(N, 3) ``bump_normal(n, dpdu, dpdv, uv)``."""
        if self.bump_mode == 0:
            return n
        if self.bump_mode == 1:
            g = height_gradient_bumps(uv, self.scale)
        else:
            g = height_gradient_image(uv, self.scale, self.height)
        return bump_normal(n, dpdu, dpdv, g, float(self.material.bump_scale))
