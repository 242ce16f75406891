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

import moderngl
import numpy as np

from shadelab.gl.programs import set_uniform
from shadelab.scene.model import Material
from shadelab.shading.surface_detail import (  # noqa: F401  (re-exported, the pure half)
    BUMP_MODES,
    LIMIT_ENV,
    MAX_TEXTURE_PIXELS,
    TEXTURE_MODES,
    check_image_file,
    check_image_size,
    has_surface_detail,
    load_image,
    srgb_to_linear,
    texture_limit,
)


def fit_texture(pixels: np.ndarray, limit: int, key: str = "texture") -> np.ndarray:
    """The image as a GL texture can hold it: a side over ``limit`` (GL_MAX_TEXTURE_SIZE;
    a larger one is GL_INVALID_VALUE and draws black) is box-filtered down, the aspect kept,
    with a one-line note. The CPU renderers sample the full image."""
    h, w = pixels.shape[:2]
    if max(w, h) <= limit:
        return pixels
    from PIL import Image

    scale = limit / max(w, h)
    size = (min(max(int(round(w * scale)), 1), limit), min(max(int(round(h * scale)), 1), limit))
    channels = pixels[..., None] if pixels.ndim == 2 else pixels
    out = np.stack([np.asarray(Image.fromarray(np.ascontiguousarray(channels[..., c]), "F")
                               .resize(size, Image.Resampling.BOX), dtype=np.float32)
                    for c in range(channels.shape[2])], axis=-1)
    from shadelab.progress import note

    note(f"{key}: {w}x{h} image resampled to {size[0]}x{size[1]} for the raster "
         f"(GL_MAX_TEXTURE_SIZE {limit})")
    return np.ascontiguousarray(out[..., 0] if pixels.ndim == 2 else out)


class TextureCache:
    """GPU textures for image files, keyed by resolved path and kind; made on first use."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self._textures: dict[tuple[str, str, bool], moderngl.Texture] = {}

    def get(self, path: str, base_dir: str, key: str, height: bool) -> moderngl.Texture:
        slot = (path, base_dir, height)
        if slot not in self._textures:
            pixels = fit_texture(load_image(path, base_dir, key, height),
                                 int(self.ctx.info.get("GL_MAX_TEXTURE_SIZE", 4096)), key)
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
