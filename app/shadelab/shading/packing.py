"""Materials, lights and uniforms packed once, in numpy, for the GL renderer and the numba
kernels: the one place a scene's records become the arrays and bytes the shaders
(``shaders/include/lighting.glsl``) and :mod:`shadelab.shading.kernels` read.

- :func:`reflectance` is rho = kd Od, computed here and nowhere else (the premultiplied
  uniforms, the path tracer, radiosity's patches all call it);
- :func:`pack_material` / :func:`material_uniforms` / :func:`premultiplied_uniforms`: a
  material's GL uniforms. kd travels one way: ``Material.kd`` -> :func:`pack_material` ->
  :meth:`shadelab.raster.renderer.Renderer.write_material` -> ``u_kd`` (or its folded
  ``u_light_diffuse = S_i Ip,i kd Od`` in a PREMULTIPLIED program);
- :func:`pack_lights` / :func:`light_uniform_arrays`: the lights for the GL uniforms, and
  :func:`light_table` / :func:`material_table` for the kernels, from the same packing.
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass

import numpy as np

from shadelab.constants import SHADING_EPS
from shadelab.scene.model import MAX_LIGHTS, Light, Material
from shadelab.shading.codes import ATTENUATION_CODES
from shadelab.shading.lights import light_kind

# ------------------------------------------------------------------------------ materials
# The numba kernels' material table columns
M_KA, M_KD, M_KS, M_N, M_OD, M_OS, M_LE = 0, 1, 2, 3, 4, 7, 10
MATERIAL_COLUMNS = 13
# The scalar material uniforms of lighting.glsl
MATERIAL_FLOATS = ("u_ka", "u_kd", "u_ks", "u_n")


def reflectance(material: Material) -> np.ndarray:
    """(3,) rho = kd Od, the diffuse reflectance (radiosity's rho, the path tracer's diffuse
    albedo, the raster's folded diffuse factor)."""
    return material.kd * np.asarray(material.Od, dtype=np.float64)


def textured_reflectance(kd: np.ndarray, od: np.ndarray) -> np.ndarray:
    """(N, 3) rho = kd Od at N points of textured surfaces: kd (N,) and the texture's Od (N, 3)."""
    return kd[:, None] * od


@dataclass(frozen=True)
class PackedMaterial:
    """One material's coefficients as the renderers read them (float64)."""

    ka: float
    kd: float
    ks: float
    n: float
    Od: np.ndarray        # (3,)
    Os: np.ndarray        # (3,)
    emission: np.ndarray  # (3,) Le
    rho: np.ndarray       # (3,) kd Od
    specular: np.ndarray  # (3,) ks Os


def material_key(material: Material) -> tuple:
    """The values a material's uniforms depend on (a cache key)."""
    return (material.ka, material.kd, material.ks, material.n, *material.Od, *material.Os,
            *material.emission)


def pack_material(material: Material) -> PackedMaterial:
    od = np.asarray(material.Od, dtype=np.float64)
    os_ = np.asarray(material.Os, dtype=np.float64)
    return PackedMaterial(material.ka, material.kd, material.ks, material.n, od, os_,
                          np.asarray(material.emission, dtype=np.float64),
                          reflectance(material), material.ks * os_)


def material_uniforms(packed: PackedMaterial) -> dict[str, bytes]:
    """The raw uniforms ``u_ka``, ``u_kd``, ``u_ks``, ``u_n``, ``u_Od``, ``u_Os``,
    ``u_emission`` as bytes."""
    floats = (packed.ka, packed.kd, packed.ks, packed.n)
    out = {name: struct.pack("f", v) for name, v in zip(MATERIAL_FLOATS, floats, strict=True)}
    out["u_Od"] = packed.Od.astype(np.float32).tobytes()
    out["u_Os"] = packed.Os.astype(np.float32).tobytes()
    out["u_emission"] = packed.emission.astype(np.float32).tobytes()
    return out


def premultiplied_uniforms(packed: PackedMaterial, Ia: np.ndarray, ip_s: np.ndarray,
                           ambient_on: float) -> dict[str, np.ndarray]:
    """What a PREMULTIPLIED program reads (float32): ``u_ambient`` = on (Le + Ia ka Od),
    ``u_light_diffuse[i]`` = S_i Ip,i kd Od and ``u_light_specular[i]`` = S_i Ip,i ks Os, with
    ``ip_s`` (L, 3) the lights' S_i Ip,i."""
    ambient = ambient_on * (packed.emission + Ia * packed.ka * packed.Od)
    return {"u_ambient": ambient.astype(np.float32),
            "u_light_diffuse": (ip_s * packed.rho).astype(np.float32),
            "u_light_specular": (ip_s * packed.specular).astype(np.float32)}


def material_table(materials: list[Material]) -> np.ndarray:
    """(M, 13) float64 for the kernels: ka, kd, ks, n, Od, Os, emission."""
    table = np.zeros((max(len(materials), 1), MATERIAL_COLUMNS))
    for i, m in enumerate(materials):
        table[i, :4] = (m.ka, m.kd, m.ks, m.n)
        table[i, M_OD:M_OD + 3] = m.Od
        table[i, M_OS:M_OS + 3] = m.Os
        table[i, M_LE:M_LE + 3] = m.emission
    return table


# ------------------------------------------------------------------------------ lights
# The numba kernels' light table columns
L_KIND, L_POS, L_DIR, L_IP = 0, 1, 4, 7
L_ATT, L_C1, L_C2, L_C3, L_COS, L_EXP = 10, 11, 12, 13, 14, 15
LIGHT_COLUMNS = 16


@dataclass
class PackedLights:
    """L lights as arrays (float64, world space)."""

    kind: np.ndarray         # (L,) int32, the light classes' codes
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
        out.kind[i] = light_kind(light).code
        out.attenuation[i] = ATTENUATION_CODES[light.attenuation]
        out.position[i] = light.position
        out.direction[i] = direction / length if length > SHADING_EPS else 0.0
        out.Ip[i] = light.Ip
        out.c[i] = (light.c1, light.c2, light.c3)
        out.spot[i] = (math.cos(math.radians(light.cone_angle)), light.spot_exponent)
    return out


def light_table(lights: list[Light]) -> np.ndarray:
    """(L, 16) float64 for the kernels: kind, position, unit direction, Ip, attenuation,
    c1-c3, cos cone, e (from :func:`pack_lights`, as the GL uniforms are)."""
    packed = pack_lights(lights)
    table = np.zeros((len(lights), LIGHT_COLUMNS))
    table[:, L_KIND] = packed.kind
    table[:, L_POS:L_POS + 3] = packed.position
    table[:, L_DIR:L_DIR + 3] = packed.direction
    table[:, L_IP:L_IP + 3] = packed.Ip
    table[:, L_ATT] = packed.attenuation
    table[:, L_C1:L_C3 + 1] = packed.c
    table[:, L_COS] = packed.spot[:, 0]
    table[:, L_EXP] = packed.spot[:, 1]
    return table


def light_uniform_arrays(lights: list[Light],
                         shadow: list[float] | None = None) -> dict[str, np.ndarray]:
    """The ``u_light_*`` arrays of ``lighting.glsl`` (padded to MAX_LIGHTS) from
    :func:`pack_lights`, the packing the kernels' table uses, and ``u_num_lights`` (int32,
    one element)."""
    count = min(len(lights), MAX_LIGHTS)
    packed = pack_lights(lights[:count])
    s = np.ones(MAX_LIGHTS, np.float32)
    if shadow is not None:
        s[:count] = shadow[:count]
    arrays = {"u_num_lights": np.array([count], np.int32)}
    for name, array in (("u_light_kind", packed.kind), ("u_light_attenuation", packed.attenuation),
                        ("u_light_position", packed.position),
                        ("u_light_direction", packed.direction), ("u_light_Ip", packed.Ip),
                        ("u_light_c", packed.c), ("u_light_spot", packed.spot)):
        padded = np.zeros((MAX_LIGHTS, *array.shape[1:]), array.dtype)
        padded[:count] = array
        arrays[name] = padded.astype(np.int32 if array.dtype.kind == "i" else np.float32)
    arrays["u_light_S"] = s
    return arrays
