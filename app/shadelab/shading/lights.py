"""The lecture's light kinds as small classes (after pyrender's ``pyrender/light.py``).

A preset names a light's kind as a string (``kind = "point" | "directional" | "spot"`` in
TOML, :class:`shadelab.scene.model.Light`); :func:`light_kind` turns it into one of these
classes, which carry what differs from kind to kind, in numpy:

- ``code``: the integer the GL uniforms, the shader variants' ``LIGHT_KINDS`` bits and the
  numba light table store (:mod:`shadelab.shading.codes` builds its table from these);
- :meth:`LightKind.to_light`: the unit vectors L from surface points to the light and the
  distances (inf for a light at infinity);
- :meth:`LightKind.attenuation`: f_att at those distances (1 at infinity);
- :meth:`LightKind.spot`: the cone factor (1 but for a spot);
- :meth:`LightKind.homogeneous`: the light as a homogeneous point (w = 0 at infinity), what
  shadow volumes are extruded from; :meth:`LightKind.end`: where a shadow ray to it ends.

:func:`attenuation` (f_att of a mode) and :func:`spot_factor` (Warn's cone) are the numpy
terms the classes apply; :mod:`shadelab.shading.reference` re-exports them.

A new kind is a subclass here (with the next free ``code``), its name in
``scene.model.LIGHT_KINDS``, and its branch in ``shaders/include/lighting.glsl`` and in
:mod:`shadelab.shading.kernels` (ARCHITECTURE.md).
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from shadelab.constants import SHADING_EPS as _EPS
from shadelab.scene.model import Light
from shadelab.shading.vectors import dot, normalize


def attenuation(distance: np.ndarray, mode: str, c1: float, c2: float, c3: float) -> np.ndarray:
    """Light-source attenuation f_att at ``distance`` (inf for a directional light: 1).

    Notes
    -----
    none:           f_att = 1
    inverse_square: f_att = 1 / d^2
    lecture:        f_att = min(1 / (c1 + c2 d + c3 d^2), 1)
    """
    d = np.asarray(distance, dtype=np.float64)
    finite = np.isfinite(d)
    dd = np.where(finite, d, 0.0)
    if mode == "none":
        f = np.ones_like(dd)
    elif mode == "inverse_square":
        f = 1.0 / np.maximum(dd * dd, _EPS)
    elif mode == "lecture":
        denominator = c1 + c2 * dd + c3 * dd * dd
        f = np.minimum(1.0 / np.maximum(denominator, _EPS), 1.0)
    else:
        raise ValueError(f"unknown attenuation mode {mode!r}")
    return np.where(finite, f, 1.0)


def spot_factor(to_light: np.ndarray, axis: np.ndarray, cos_cone: float,
                exponent: float) -> np.ndarray:
    """Spotlight cone (Warn): (cos phi)^e inside the cone, 0 outside.

    Notes
    -----
    cos phi = (-L) . D, with D the unit spot axis; inside when phi <= cone angle.
    """
    cos_phi = dot(-to_light, axis)
    inside = cos_phi >= cos_cone
    return np.where(inside, np.power(np.maximum(cos_phi, 0.0), exponent), 0.0)


class LightKind:
    """One light of the scene seen through its kind; ``light`` is the preset's record."""

    kind: ClassVar[str]
    code: ClassVar[int]
    at_infinity: ClassVar[bool] = False   # directional: no position, no f_att
    aimed: ClassVar[bool] = False         # its ``direction`` must be a non-zero vector
    has_cone: ClassVar[bool] = False      # spot: ``cone_angle`` and ``spot_exponent`` apply

    def __init__(self, light: Light):
        self.light = light

    def to_light(self, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Unit ``to_light`` vectors (..., 3) and distances (...) from surface points."""
        position = np.asarray(position, dtype=np.float64)
        delta = np.asarray(self.light.position, dtype=np.float64) - position
        distance = np.linalg.norm(delta, axis=-1)
        return normalize(delta), distance

    def attenuation(self, distance: np.ndarray) -> np.ndarray:
        """f_att at ``distance`` (the light's mode and c1, c2, c3; 1 at infinite distance)."""
        light = self.light
        return attenuation(distance, light.attenuation, light.c1, light.c2, light.c3)

    def spot(self, to_light: np.ndarray) -> np.ndarray:
        """The cone factor at each point: 1 for a light without a cone."""
        return np.ones(np.shape(to_light)[:-1])

    def homogeneous(self) -> np.ndarray:
        """(4,) the light's homogeneous position: (position, 1)."""
        return np.append(np.asarray(self.light.position, dtype=np.float64), 1.0)

    def end(self) -> np.ndarray | None:
        """Where a shadow ray to this light ends (None: at infinity)."""
        return np.asarray(self.light.position, float)


class PointLight(LightKind):
    """Light from a point, in every direction."""

    kind = "point"
    code = 0


class DirectionalLight(LightKind):
    """Parallel light from infinitely far along ``-direction``: L is the same everywhere."""

    kind = "directional"
    code = 1
    at_infinity = True
    aimed = True

    def to_light(self, position: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        position = np.asarray(position, dtype=np.float64)
        to_light = normalize(-np.asarray(self.light.direction, dtype=np.float64))
        to_light = np.broadcast_to(to_light, position.shape)
        return to_light, np.full(position.shape[:-1], np.inf)

    def homogeneous(self) -> np.ndarray:
        """(4,) the point at infinity towards the light: (-direction / |direction|, 0)."""
        d = np.asarray(self.light.direction, dtype=np.float64)
        return np.append(-d / max(np.linalg.norm(d), 1e-300), 0.0)

    def end(self) -> None:
        return None


class SpotLight(PointLight):
    """A point light restricted to a cone about ``direction`` (Warn's (cos phi)^e falloff)."""

    kind = "spot"
    code = 2
    aimed = True
    has_cone = True

    def spot(self, to_light: np.ndarray) -> np.ndarray:
        light = self.light
        axis = normalize(np.asarray(light.direction, dtype=np.float64))
        return spot_factor(to_light, axis, np.cos(np.radians(light.cone_angle)),
                           light.spot_exponent)


LIGHT_CLASSES: tuple[type[LightKind], ...] = (PointLight, DirectionalLight, SpotLight)
KINDS: dict[str, type[LightKind]] = {cls.kind: cls for cls in LIGHT_CLASSES}


def light_kind(light: Light) -> LightKind:
    """The :class:`LightKind` of a scene light (its ``kind`` string looked up once)."""
    return KINDS[light.kind](light)
