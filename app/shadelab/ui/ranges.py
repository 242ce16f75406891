"""Slider ranges read from the model's field table (``shadelab.scene.model.spec``).

One source of truth: a slider never goes outside the field's validation range (lo, hi).
Where that range is huge (``n`` up to 1e5, ``c1`` up to 1e12), the slider shows a *soft*
range where the lecture's values live, linear there; the soft top grows in 1-2-5 steps to
hold a larger value a preset brought or one typed with Ctrl+click (never past the spec's hi),
so dragging is stable (the top only moves when the value passes it).
"""

from __future__ import annotations

import math
from dataclasses import fields

from imgui_bundle import imgui

from shadelab.scene.model import Light, Material, Object, RenderSettings

# (class, field) -> (soft lo, soft hi, logarithmic, format). lo/hi are clamped to the spec.
SOFT = {
    (Material, "ka"): (0.0, 1.0, False, "%.3f"),
    (Material, "kd"): (0.0, 1.0, False, "%.3f"),
    (Material, "ks"): (0.0, 1.0, False, "%.3f"),
    (Material, "n"): (0.0, 200.0, False, "%.1f"),
    (Material, "kt"): (0.0, 1.0, False, "%.3f"),
    (Material, "kr"): (-1.0, 1.0, False, "%.3f"),
    (Material, "ior"): (1.0, 3.0, False, "%.3f"),
    (Light, "c1"): (0.0, 2.0, False, "%.4g"),
    (Light, "c2"): (0.0, 1.0, False, "%.4g"),
    (Light, "c3"): (0.0, 0.2, False, "%.4g"),
    (Light, "cone_angle"): (0.0, 90.0, False, "%.1f"),
    (Light, "spot_exponent"): (0.0, 100.0, False, "%.1f"),
    (Object, "crease_angle"): (0.0, 180.0, False, "%.1f"),
    (RenderSettings, "exposure"): (0.01, 100.0, True, "%.3g"),
}


def spec_range(cls: type, name: str) -> tuple[float, float]:
    """The (lo, hi) a ``float``/``int`` field's spec allows."""
    for f in fields(cls):
        if f.name == name:
            kind, *args = f.metadata["spec"]
            if kind in ("float", "int"):
                return float(args[0]), float(args[1])
            if kind in ("rgb",):
                return 0.0, float(args[0])
            if kind == "rgb01":
                return 0.0, 1.0
            raise ValueError(f"{cls.__name__}.{name}: a '{kind}' field has no slider range")
    raise KeyError(f"{cls.__name__}.{name}")


def nice_ceiling(value: float) -> float:
    """The smallest 1, 2 or 5 x 10^k that is >= value (value > 0)."""
    k = math.floor(math.log10(value))
    for m in (1.0, 2.0, 5.0, 10.0):
        if m * 10.0 ** k >= value * (1 - 1e-12):
            return m * 10.0 ** k
    return 10.0 ** (k + 1)


def slider_range(cls: type, name: str, value: float) -> tuple[float, float, bool, str]:
    """(lo, hi, logarithmic, format) of the slider showing ``value``."""
    lo, hi = spec_range(cls, name)
    soft_lo, soft_hi, log, fmt = SOFT.get((cls, name), (lo, hi, False, "%.3g"))
    top = soft_hi if value <= soft_hi else nice_ceiling(value)
    return max(lo, soft_lo), min(hi, top), log, fmt


def field_slider(cls: type):
    """A ``(label, value) -> (changed, value)`` widget for a float field of ``cls``: the
    slider's range from :func:`slider_range`, a typed value clamped to the spec."""
    def widget(label: str, value: float) -> tuple[bool, float]:
        lo, hi, log, fmt = slider_range(cls, label, float(value))
        flags = imgui.SliderFlags_.logarithmic if log else 0
        changed, new = imgui.slider_float(label, float(value), lo, hi, fmt, flags)
        if not math.isfinite(new):  # typed nan, inf or 1e309: the value is kept
            return False, value
        spec_lo, spec_hi = spec_range(cls, label)
        return changed, float(min(max(new, spec_lo), spec_hi))
    return widget


def finite(changed: bool, new, old) -> tuple[bool, object]:
    """A widget's (changed, value), with a typed nan, inf or 1e309 (in any component) refused:
    the old value is kept and nothing changed."""
    values = new if isinstance(new, (tuple, list)) else (new,)
    if all(math.isfinite(float(v)) for v in values):
        return changed, new
    return False, old


def intensity_range(value: float, soft_hi: float = 2.0, hi: float = 1e12) -> float:
    """Top of a linear intensity slider: ``soft_hi``, or the 1-2-5 step above a larger value."""
    return min(hi, soft_hi if value <= soft_hi else nice_ceiling(value))
