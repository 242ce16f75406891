"""The lighting equation in every form: the numpy reference (reference.py), the light kinds
(lights.py), the packing of materials, lights and uniforms for the GL renderer and the numba
kernels (packing.py), the numba local model (kernels.py); shaders/include/lighting.glsl is its
GLSL mirror (found by :func:`shadelab.resources.shaders_dir`)."""

from shadelab.shading.reference import shade, shade_terms  # noqa: F401
