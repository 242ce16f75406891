"""The integer codes that the lighting equation's switches take on the GPU and in the numba
kernels: one table, from which the GLSL ``#define``s are generated (``LIGHT_POINT`` ...,
see :func:`glsl_defines` and :func:`shadelab.gl.programs.register_includes`), so no copy of
a code is written by hand anywhere else.
"""

from __future__ import annotations

from shadelab.constants import SHADING_EPS
from shadelab.scene.model import (
    AIMED_LIGHT_KINDS,
    ATTENUATION_MODES,
    LIGHT_KINDS,
    MAX_LIGHTS,
    SPECULAR_MODELS,
)
from shadelab.shading.lights import LIGHT_CLASSES

LIGHT_KIND_CODES = {cls.kind: cls.code for cls in LIGHT_CLASSES}  # Light.kind, from lights.py
ATTENUATION_CODES = {"none": 0, "inverse_square": 1, "lecture": 2}  # Light.attenuation
SPECULAR_CODES = {"phong": 0, "blinn": 1}  # (R.V)^n or (N.H)^n
# The equation's terms a viewer may switch off one by one (issue 22: click a term of the
# caption): ambient Ia ka Od, diffuse kd Od (N.L_i), specular ks Os (R_i.V)^n, the attenuation
# f_att,i (off: 1) and the shadow factor S_i (off: 1). One bit each in ``u_terms_off``
# (lighting.glsl's TERM_AMBIENT ...); shadelab.shading.reference.shade_terms(off=...) is the
# numpy truth.
TERM_BITS = {"ambient": 1, "diffuse": 2, "specular": 4, "attenuation": 8, "shadow": 16}
TERMS = tuple(TERM_BITS)

assert tuple(LIGHT_KIND_CODES) == LIGHT_KINDS
assert tuple(cls.kind for cls in LIGHT_CLASSES if cls.aimed) == AIMED_LIGHT_KINDS
assert tuple(ATTENUATION_CODES) == ATTENUATION_MODES
assert tuple(SPECULAR_CODES) == SPECULAR_MODELS
# A shader variant packs each light's kind and attenuation codes in CODE_BITS bits
# (Renderer.light_defines, LIGHT_KIND(i) in lighting.glsl)
CODE_BITS = 2
assert max(LIGHT_KIND_CODES.values()) < 1 << CODE_BITS
assert max(ATTENUATION_CODES.values()) < 1 << CODE_BITS

# GLSL name prefix of each table: LIGHT_SPOT, ATTENUATION_LECTURE, SPECULAR_BLINN
_GLSL_TABLES = (("LIGHT", LIGHT_KIND_CODES), ("ATTENUATION", ATTENUATION_CODES),
                ("SPECULAR", SPECULAR_CODES), ("TERM", TERM_BITS))


def glsl_defines() -> dict[str, object]:
    """Every code as a GLSL ``#define`` (name -> value), with MAX_LIGHTS and SHADING_EPS."""
    defines: dict[str, object] = {"MAX_LIGHTS": MAX_LIGHTS, "SHADING_EPS": repr(SHADING_EPS)}
    for prefix, table in _GLSL_TABLES:
        defines.update({f"{prefix}_{name.upper()}": code for name, code in table.items()})
    return defines


def terms_mask(off) -> int:
    """The ``u_terms_off`` bits of the term names in ``off`` (an unknown name: ValueError)."""
    mask = 0
    for name in off:
        if name not in TERM_BITS:
            raise ValueError(f"term '{name}': expected one of {', '.join(TERMS)}")
        mask |= TERM_BITS[name]
    return mask


def glsl_header() -> str:
    """The ``#define`` lines of :func:`glsl_defines`, for the head of an include."""
    lines = [f"#define {name} {value}" for name, value in glsl_defines().items()]
    return "// Generated from shadelab/shading/codes.py and shadelab/constants.py.\n" + \
        "\n".join(lines) + "\n"
