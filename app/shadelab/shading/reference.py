"""The lighting equation of the lecture, once, in vectorized numpy.

Conventions (see :mod:`shadelab.shading.conventions`): ``to_light`` and ``to_eye`` point away from
the surface; normals are unit; colors are linear RGB; arrays broadcast over leading axes
(``(..., 3)`` vectors, ``(...)`` scalars).

``shaders/include/lighting.glsl`` mirrors every function here with the same name and
argument order; ``tests/shading/test_glsl_parity.py`` holds the two together.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from shadelab.constants import SHADING_EPS as _EPS
from shadelab.scene.model import Light, Material
from shadelab.shading.codes import TERM_BITS, TERMS, terms_mask  # noqa: F401 (switchable)
from shadelab.shading.lights import attenuation, light_kind, spot_factor  # noqa: F401
from shadelab.shading.vectors import dot as _dot
from shadelab.shading.vectors import normalize


def lambert(n: np.ndarray, to_light: np.ndarray) -> np.ndarray:
    """Lambert's cosine law, clamped.

    Notes
    -----
    cos(theta) = max(N . L, 0)
    """
    return np.maximum(_dot(n, to_light), 0.0)


def reflect_light(n: np.ndarray, to_light: np.ndarray) -> np.ndarray:
    """The mirror direction of ``to_light`` about ``n``.

    Notes
    -----
    R = 2 N (N . L) - L
    """
    return 2.0 * n * _dot(n, to_light)[..., None] - to_light


def _power(cosine: np.ndarray, shininess: np.ndarray) -> np.ndarray:
    """cos^n for cos > 0, else 0; n = 0 gives 1 inside the lobe (no 0^0 ambiguity)."""
    c = np.maximum(cosine, 0.0)
    return np.where(c > 0.0, np.power(np.maximum(c, _EPS), shininess), 0.0)


def phong_specular(n: np.ndarray, to_light: np.ndarray, to_eye: np.ndarray,
                   shininess: np.ndarray) -> np.ndarray:
    """Phong's specular term; zero where the light is behind the surface.

    Notes
    -----
    (R . V)^n with R = 2 N (N . L) - L
    """
    lit = _dot(n, to_light) > 0.0
    return np.where(lit, _power(_dot(reflect_light(n, to_light), to_eye), shininess), 0.0)


def halfway(to_light: np.ndarray, to_eye: np.ndarray) -> np.ndarray:
    """H = (L + V) / |L + V|; zero when L = -V (guarded)."""
    return normalize(to_light + to_eye)


def blinn_phong_specular(n: np.ndarray, to_light: np.ndarray, to_eye: np.ndarray,
                         shininess: np.ndarray) -> np.ndarray:
    """Blinn-Phong's specular term; zero where the light is behind the surface.

    Notes
    -----
    (N . H)^n with H = (L + V) / |L + V|
    """
    lit = _dot(n, to_light) > 0.0
    return np.where(lit, _power(_dot(n, halfway(to_light, to_eye)), shininess), 0.0)


def attenuation_clamped(distance: np.ndarray, light: Light) -> np.ndarray:
    """True where the lecture's min(..., 1) clamp is active (the probe shows it)."""
    if light.attenuation != "lecture":
        return np.zeros(np.shape(distance), dtype=bool)
    d = np.asarray(distance, dtype=np.float64)
    finite = np.isfinite(d)
    dd = np.where(finite, d, 0.0)
    return finite & ((light.c1 + light.c2 * dd + light.c3 * dd * dd) <= 1.0)


def light_vectors(light: Light, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Unit ``to_light`` vectors and distances from surface points to a light.

    A directional light is at infinite distance along ``-direction``
    (:meth:`shadelab.shading.lights.LightKind.to_light`).
    """
    return light_kind(light).to_light(position)


TERM_AMBIENT, TERM_DIFFUSE, TERM_SPECULAR, TERM_ATTENUATION, TERM_SHADOW = (
    TERM_BITS[name] for name in ("ambient", "diffuse", "specular", "attenuation", "shadow"))


@dataclass
class LightTerms:
    """One light's contribution at each point, split the way the lecture writes it."""

    to_light: np.ndarray      # (..., 3) unit
    distance: np.ndarray      # (...) world units, inf for directional
    f_att: np.ndarray         # (...) attenuation
    clamp_active: np.ndarray  # (...) bool, lecture's min(., 1) clamped to 1
    spot: np.ndarray          # (...) spot cone factor (1 for other kinds)
    shadow: np.ndarray        # (...) S_i in [0, 1], or (..., 3) when kt-filtered per channel
    diffuse: np.ndarray       # (..., 3) S f_att spot Ip kd Od (N.L)
    specular: np.ndarray      # (..., 3) S f_att spot Ip ks Os (R.V)^n or (N.H)^n


@dataclass
class ShadeTerms:
    emission: np.ndarray      # (..., 3) self-luminous radiance (area lights), 0 elsewhere
    ambient: np.ndarray       # (..., 3) Ia ka Od
    lights: list[LightTerms]

    @property
    def total(self) -> np.ndarray:
        out = self.emission + self.ambient
        for term in self.lights:
            out = out + term.diffuse + term.specular
        return out


def _material_arrays(material: Material, od: np.ndarray | None, shape: tuple):
    od_arr = np.asarray(material.Od if od is None else od, dtype=np.float64)
    return np.broadcast_to(od_arr, shape + (3,)), np.asarray(material.Os, dtype=np.float64)


def shadow_filter(material: Material) -> np.ndarray:
    """(3,) the factor one crossing of a transparent caster puts on S_i: kt Ot for the
    "filtered" model, kt for "interpolated" (whose Ot is taken as 1); 0 for opaque ones."""
    tint = material.Ot if material.transparency == "filtered" else (1.0, 1.0, 1.0)
    return material.kt * np.asarray(tint, dtype=np.float64)


def terminator_softening(n_dot_l: np.ndarray, threshold) -> np.ndarray:
    """The self-shadow part of S_i on a smooth mesh: smoothstep(t, 2t, N.L), t = ``threshold``
    (a number, or one per point: :func:`shadelab.geometry.normals.threshold_at`).

    Shadow volumes follow the faces: a face turned from the light is inside its own volume
    (S_i = 0) while its interpolated normal can still see the light, up to N.L = t
    (:func:`shadelab.geometry.normals.corner_sines`). Fading the light to 0 at N.L = t
    joins the lit side to those faces with no step; t = 0 (flat meshes) leaves S_i = 1.
    """
    n_dot_l = np.asarray(n_dot_l, dtype=np.float64)
    t = np.broadcast_to(np.asarray(threshold, dtype=np.float64), n_dot_l.shape)
    on = t > 0.0
    x = np.clip((n_dot_l - t) / np.where(on, t, 1.0), 0.0, 1.0)
    return np.where(on, x * x * (3.0 - 2.0 * x), 1.0)


def shade_terms(position: np.ndarray, normal: np.ndarray, eye: np.ndarray, material: Material,
                lights: list[Light], Ia, specular: str = "phong",
                shadow: list[np.ndarray] | None = None,
                od: np.ndarray | None = None, terminator=0.0, off=()) -> ShadeTerms:
    """Every term of the lecture's equation at each point.

    Parameters
    ----------
    position : (..., 3) float, world space
    normal : (..., 3) float, unit, world space (flipped by the caller for back faces)
    eye : (3,) float, world space camera position
    material : the coefficients ka, kd, ks, n, Od, Os
    lights : the enabled lights, each with its Ip, attenuation and cone
    Ia : (3,) ambient intensity
    specular : "phong" for (R.V)^n or "blinn" for (N.H)^n
    shadow : one S_i array (...) per light, 1 = lit, or (..., 3) per channel (the kt-filtered
        S_i of transparent casters); default all lit
    od : (..., 3) optional per-point diffuse color (textures), replacing material.Od
    terminator : the terminator threshold t (shadow volumes on), a number or (...) per point;
        S_i is multiplied by :func:`terminator_softening` (N.L_i, t). 0 (the default): none
    off : names from :data:`TERMS` switched off (issue 22, a click on the caption's term):
        "ambient" (Ia ka Od = 0; Le stays), "diffuse" and "specular" (= 0), "attenuation"
        (f_att,i = 1) and "shadow" (S_i = 1, the terminator fade with it); lighting.glsl's
        ``u_terms_off`` bits mirror them

    Notes
    -----
    I = Le + Ia ka Od + sum_i S_i f_att,i Ip,i [kd Od (N.L_i) + ks Os (R_i.V)^n]

    Le is the material's emission (zero but for self-luminous surfaces such as the Cornell
    box's ceiling light), so an area light is visible in every renderer.
    """
    position = np.asarray(position, dtype=np.float64)
    n = np.asarray(normal, dtype=np.float64)
    shape = position.shape[:-1]
    od_arr, os_arr = _material_arrays(material, od, shape)
    to_eye = normalize(np.asarray(eye, dtype=np.float64) - position)
    mask = terms_mask(off)
    ambient = np.asarray(Ia, dtype=np.float64) * material.ka * od_arr
    if mask & TERM_AMBIENT:
        ambient = np.zeros_like(ambient)
    kd = 0.0 if mask & TERM_DIFFUSE else material.kd
    ks = 0.0 if mask & TERM_SPECULAR else material.ks
    if mask & TERM_SHADOW:
        shadow, terminator = None, 0.0
    spec_fn = blinn_phong_specular if specular == "blinn" else phong_specular
    terms = []
    for i, light in enumerate(lights):
        kind = light_kind(light)
        to_light, distance = kind.to_light(position)
        f_att = kind.attenuation(distance)
        if mask & TERM_ATTENUATION:
            f_att = np.ones_like(f_att)
        spot = kind.spot(to_light)
        s = np.ones(shape) if shadow is None else np.asarray(shadow[i], dtype=np.float64)
        rgb = s.shape == shape + (3,) and shadow is not None   # kt-filtered S_i per channel
        if not rgb:
            s = np.broadcast_to(s, shape)
        if np.any(np.asarray(terminator) > 0.0):
            soft = terminator_softening(np.sum(n * to_light, axis=-1), terminator)
            s = s * (soft[..., None] if rgb else soft)
        s3 = s if rgb else s[..., None]
        scale = s3 * (f_att * spot)[..., None] * np.asarray(light.Ip, dtype=np.float64)
        diffuse = scale * kd * od_arr * lambert(n, to_light)[..., None]
        spec = scale * ks * os_arr * spec_fn(n, to_light, to_eye, material.n)[..., None]
        terms.append(LightTerms(to_light, distance, f_att, attenuation_clamped(distance, light),
                                spot, s, diffuse, spec))
    emission = np.broadcast_to(np.asarray(material.emission, dtype=np.float64), shape + (3,))
    return ShadeTerms(emission, ambient, terms)


def shade(position: np.ndarray, normal: np.ndarray, eye: np.ndarray, material: Material,
          lights: list[Light], Ia, specular: str = "phong",
          shadow: list[np.ndarray] | None = None, od: np.ndarray | None = None,
          terminator=0.0, off=()) -> np.ndarray:
    """The lecture's illumination I (..., 3) at each point; see :func:`shade_terms`.

    Notes
    -----
    I = Ia ka Od + sum_i S_i f_att,i Ip,i [kd Od (N.L_i) + ks Os (R_i.V)^n]
    """
    return shade_terms(position, normal, eye, material, lights, Ia, specular, shadow, od,
                       terminator, off).total
