"""Surface detail for the raster renderer: texture-mapped Od and bump maps, per material.

``Material.texture`` is ``""`` (none), ``"checker"`` (procedural: Od and texture_color2) or an
image path; ``Material.bump`` is ``""``, ``"bumps"`` (procedural sine bumps) or a height-map
image path (gray levels, 0 = low, white = high). Paths are relative to the preset's folder.
Color images are sRGB-encoded files and are decoded to linear RGB; height maps are used as
stored. ``texture_scale`` repeats both patterns across [0, 1] uv. The GLSL side is
``shaders/include/surface.glsl`` and the ``*_tex`` programs, used only by materials with a
texture or a bump, so every other material keeps its exact output.
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path

import moderngl
import numpy as np
from PIL import Image, UnidentifiedImageError

from shadelab.errors import ShadeLabError
from shadelab.gl.programs import set_uniform
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
    full = _resolve(path, base_dir, key)
    try:
        with _open_checked(full, key) as image:
            return image.size
    except (UnidentifiedImageError, OSError) as exc:
        raise ShadeLabError(f"{key}: '{full.name}' could not be read as an image ({exc})") from None


def load_image(path: str, base_dir: str, key: str, height: bool = False) -> np.ndarray:
    """(H, W, 3) linear RGB or (H, W) height in [0, 1], float32, row 0 at the BOTTOM (GL's v)."""
    full = _resolve(path, base_dir, key)
    try:
        with _open_checked(full, key) as image:
            pixels = np.asarray(image.convert("L" if height else "RGB"), dtype=np.float32)
    except (UnidentifiedImageError, OSError) as exc:
        raise ShadeLabError(f"{key}: '{full.name}' could not be read as an image ({exc})") from None
    pixels = pixels[::-1] / 255.0
    if not height:
        pixels = srgb_to_linear(pixels)
    return np.ascontiguousarray(pixels, dtype=np.float32)


class TextureCache:
    """GPU textures for image files, keyed by resolved path and kind; made on first use."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self._textures: dict[tuple[str, str, bool], moderngl.Texture] = {}

    def get(self, path: str, base_dir: str, key: str, height: bool) -> moderngl.Texture:
        slot = (path, base_dir, height)
        if slot not in self._textures:
            pixels = load_image(path, base_dir, key, height)
            h, w = pixels.shape[:2]
            texture = self.ctx.texture((w, h), 1 if height else 3, pixels.tobytes(), dtype="f4")
            texture.repeat_x = texture.repeat_y = True
            texture.filter = (moderngl.LINEAR, moderngl.LINEAR)
            self._textures[slot] = texture
        return self._textures[slot]

    def bind(self, program: moderngl.Program, name: str, material: Material,
             base_dir: str) -> None:
        """Set the surface uniforms of one material and bind its images (units 0 and 1)."""
        texture_mode = TEXTURE_MODES.get(material.texture, 2)
        bump_mode = BUMP_MODES.get(material.bump, 2)
        set_uniform(program, "u_texture_mode", texture_mode)
        set_uniform(program, "u_texture_scale", float(material.texture_scale))
        set_uniform(program, "u_texture_color2", tuple(material.texture_color2))
        set_uniform(program, "u_bump_mode", bump_mode)
        set_uniform(program, "u_bump_scale", float(material.bump_scale))
        set_uniform(program, "u_texture", 0)
        set_uniform(program, "u_bump_map", 1)
        if texture_mode == 2:
            self.get(material.texture, base_dir, f"materials.{name}.texture", False).use(0)
        if bump_mode == 2:
            self.get(material.bump, base_dir, f"materials.{name}.bump", True).use(1)

    def release(self) -> None:
        for texture in self._textures.values():
            texture.release()
        self._textures.clear()
