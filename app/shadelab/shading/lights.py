"""Lights packed into arrays, once, in numpy: what both the GL uniform writer
(:func:`shadelab.raster.renderer.write_light_uniforms`) and the numba kernels' light table
(:func:`shadelab.raytrace.kernels.light_table`) are filled from.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from shadelab.constants import SHADING_EPS
from shadelab.scene.model import Light
from shadelab.shading.codes import ATTENUATION_CODES, LIGHT_KIND_CODES


@dataclass
class PackedLights:
    """L lights as arrays (float64, world space)."""

    kind: np.ndarray         # (L,) int32, LIGHT_KIND_CODES
    attenuation: np.ndarray  # (L,) int32, ATTENUATION_CODES
    position: np.ndarray     # (L, 3) point and spot lights
    direction: np.ndarray    # (L, 3) unit, the way the light travels (0 if degenerate)
    Ip: np.ndarray           # (L, 3) linear RGB intensity
    c: np.ndarray            # (L, 3) c1, c2, c3 of the lecture's f_att
    spot: np.ndarray         # (L, 2) cos(cone half-angle), falloff exponent

    def __len__(self) -> int:
        return len(self.kind)


def pack_lights(lights: list[Light]) -> PackedLights:
    """Codes, positions, unit directions, intensities, f_att coefficients and cones."""
    count = len(lights)
    out = PackedLights(np.zeros(count, np.int32), np.zeros(count, np.int32),
                       np.zeros((count, 3)), np.zeros((count, 3)), np.zeros((count, 3)),
                       np.zeros((count, 3)), np.zeros((count, 2)))
    for i, light in enumerate(lights):
        direction = np.asarray(light.direction, dtype=np.float64)
        length = np.linalg.norm(direction)
        out.kind[i] = LIGHT_KIND_CODES[light.kind]
        out.attenuation[i] = ATTENUATION_CODES[light.attenuation]
        out.position[i] = light.position
        out.direction[i] = direction / length if length > SHADING_EPS else 0.0
        out.Ip[i] = light.Ip
        out.c[i] = (light.c1, light.c2, light.c3)
        out.spot[i] = (math.cos(math.radians(light.cone_angle)), light.spot_exponent)
    return out
