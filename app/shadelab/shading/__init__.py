"""The lighting equation, once, in numpy (mirrored by shaders/include/lighting.glsl)."""

from shadelab.shading.reference import shade, shade_terms  # noqa: F401
