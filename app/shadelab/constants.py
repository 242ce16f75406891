"""Numerical constants shared by the numpy reference, the numba kernels and the GLSL (whose
copies are generated from these, see :func:`shadelab.shading.codes.glsl_defines`).

Each constant with its unit, as pyrender's ``constants.py`` does.
"""

from __future__ import annotations

SHADING_EPS = 1e-12  # guard of the lighting equation: below it a length (world units) is 0,
#                      a cosine is not raised to a power, a denominator is clamped
T_INF = 1e30  # "no hit" ray distance, world units (finite: Embree and float32 take it)
