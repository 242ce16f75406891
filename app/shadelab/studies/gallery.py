"""The failure gallery: where each method breaks, a preset that shows it, and what ShadeLab does.

``GALLERY`` is plain data the viewer lists (name, preset, ``--set`` overrides, method,
explanation, the test that pins the failure down); :func:`render_case` draws one case with
its method, and ``shadelab gallery --out DIR`` writes one PNG per case whose renderer exists.
A method is ``raster:<shading>``, ``raytrace``, ``pathtrace[:<spp>]`` or
``radiosity[:uniform]`` (uniform: no adaptive subdivision).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class GalleryCase:
    """One failure: load ``preset`` with ``overrides`` and draw it with ``method``."""

    name: str                    # file stem of its PNG, id in the viewer
    preset: str                  # presets/<preset>.toml
    overrides: tuple[str, ...]   # --set KEY=VALUE items applied on load
    method: str                  # see the module docstring
    explanation: str             # what fails, and what ShadeLab does about it
    test_name: str               # tests/<file>::<test> that asserts the failure


T = "tests/studies/test_gallery.py::"

GALLERY: list[GalleryCase] = [
    GalleryCase(
        "gouraud-highlight", "fail-gouraud-highlight", (), "raster:gouraud",
        "Gouraud shading evaluates the equation at the vertices only: a highlight that falls "
        "inside a big triangle is never computed, so it disappears (and it smears when it sits "
        "on a vertex). Phong shading (key 3) interpolates the normal and finds it; ShadeLab "
        "defaults to Phong and the auto-quality tessellation (--error) refines spheres.",
        T + "test01_gouraud_misses_the_highlight"),
    GalleryCase(
        "mach-bands", "fail-mach-bands", (), "raster:gouraud",
        "Gouraud intensity is linear inside each triangle, so its slope jumps at every edge; the "
        "eye's lateral inhibition exaggerates such jumps into bright and dark Mach bands. Finer "
        "tessellation or Phong shading makes the slope continuous.",
        T + "test02_mach_bands_are_slope_jumps"),
    GalleryCase(
        "flat-curved", "sphere-shading", ("render.shading=flat", "objects.0.subdivisions=2"),
        "raster:flat",
        "Flat shading gives each facet one color, so a curved surface looks faceted however the "
        "light falls; the error falls only as fast as the facets shrink (see the shading "
        "chart). Use Gouraud or Phong with vertex normals on curved surfaces.",
        T + "test03_flat_shading_is_piecewise_constant"),
    GalleryCase(
        "zpass-eye-inside", "fail-zpass-eye-inside",
        ("render.shadows=volumes", "render.shadow_method=zpass"), "raster:phong",
        "z-pass stencil counting starts from zero at the eye: with the eye inside a shadow "
        "volume every count is off by one and lit and shadowed regions swap. ShadeLab uses "
        "z-fail (Carmack's reverse) with capped volumes by default, which counts from infinity.",
        T + "test04_zpass_fails_with_the_eye_inside"),
    GalleryCase(
        "non-closed-caster", "fail-open-caster", ("render.shadows=volumes",), "raster:phong",
        "Shadow volumes need closed, consistently wound casters: an open mesh has silhouette "
        "edges with one face, so its volume would leak and stencil counts go wrong. ShadeLab "
        "gives an open (or inconsistently wound) caster one small closed volume per triangle "
        "(shadelab.geometry.silhouette): the shadow stays right, at more fill cost.",
        T + "test05_open_caster"),
    GalleryCase(
        "painter-cyclic", "painter-cyclic", ("render.visibility=painter",), "raster:phong",
        "The painter's algorithm sorts whole polygons by depth; three polygons that overlap in "
        "a cycle have no correct order, so one is always drawn wrongly on top. The z-buffer "
        "(ShadeLab's default) resolves visibility per pixel.",
        T + "test06_painter_cycle"),
    GalleryCase(
        "shadow-acne", "fail-shadow-acne", ("raytrace.offset=0",), "raytrace",
        "A shadow ray starting exactly on the surface can hit that same surface through "
        "rounding, speckling lit areas with false shadow (acne). ShadeLab moves ray origins "
        "off the surface by raytrace.offset (1e-3 of the scene size by default).",
        T + "test07_shadow_acne_without_offset"),
    GalleryCase(
        "total-internal-reflection", "fail-tir", (), "raytrace",
        "Inside glass (ior 1.5) a ray meeting the surface beyond the critical angle "
        "asin(1/1.5) = 41.8 degrees cannot leave: Snell's law has no solution (the square root "
        "of a negative). ShadeLab detects it and gives the transmitted weight to the mirror ray, "
        "so the rim of the glass ball reflects instead of going black or NaN.",
        T + "test08_total_internal_reflection"),
    GalleryCase(
        "hemicube-aliasing", "cornell",
        ("radiosity.form_factors=hemicube", "radiosity.hemicube_resolution=8"), "radiosity",
        "A hemicube samples the hemisphere with a pixel grid: small or distant patches fall "
        "between pixel centres or snap to whole pixels, so form factors alias (Baum et al. "
        "1989). Raise radiosity.hemicube_resolution or use raycast/analytic form factors.",
        T + "test09_hemicube_aliasing"),
    GalleryCase(
        "radiosity-light-leak", "radiosity-leak", ("radiosity.patches=40",), "radiosity:uniform",
        "A patch that runs under a wall is lit as a whole, so light appears on the dark side "
        "(a leak); radiosity is constant per patch. Mesh along the contact lines or use more "
        "patches.",
        T + "test10_radiosity_light_leak"),
    GalleryCase(
        "degenerate-triangles", "fail-degenerate", (), "raster:gouraud",
        "A zero-area triangle has no normal. ShadeLab gives it a zero face normal, falls back to "
        "the face normal for zero-length vertex normals (the raster draws no pixel of a "
        "zero-area triangle; the numpy reference shades a zero normal as unlit, never NaN), "
        "and refuses mesh files with degenerate triangles with a one-line error.",
        T + "test11_degenerate_triangles"),
    GalleryCase(
        "shininess-zero", "fail-coefficients", ("materials.paint.n=0",), "raster:phong",
        "n = 0 makes (R.V)^n = 1 wherever the light is in front: the specular term turns into a "
        "second, flat diffuse term. ShadeLab defines 0^0 as 1 inside the lobe and 0 outside.",
        T + "test12_shininess_zero"),
    GalleryCase(
        "shininess-huge", "fail-coefficients", ("materials.paint.n=10000",), "raster:phong",
        "n = 10^4 shrinks the highlight below a pixel: pixel centres miss it and it vanishes or "
        "flickers. Nothing to fix in the model; anti-aliasing (ray tracer spp) samples it.",
        T + "test13_shininess_huge"),
    GalleryCase(
        "attenuation-zero", "fail-coefficients",
        ("lights.0.c1=0", "lights.0.c2=0", "lights.0.c3=0"), "raster:phong",
        "c1 = c2 = c3 = 0 makes 1/(c1 + c2 d + c3 d^2) infinite; the lecture's min(., 1) clamp "
        "keeps f_att = 1, so the light does not attenuate at all (no division by zero).",
        T + "test14_attenuation_zero"),
    GalleryCase(
        "intensity-zero", "fail-coefficients", ("lights.0.Ip=0,0,0",), "raster:phong",
        "Ip = 0 switches the light off: only the ambient term Ia ka Od is left (exactly, no "
        "NaN from 0 times an infinite attenuation).",
        T + "test15_intensity_zero"),
    GalleryCase(
        "energy-kd-ks", "fail-coefficients",
        ("materials.paint.kd=1", "materials.paint.ks=1", "materials.paint.Od=1,1,1"),
        "raster:phong",
        "kd + ks > 1 reflects more light than arrives: the Phong model does not conserve "
        "energy, and the highlight saturates. ShadeLab allows it for the lecture; radiosity "
        "uses only rho = kd Od and refuses a system whose rho F would not converge.",
        T + "test16_kd_plus_ks_over_one"),
]


def case_named(name: str) -> GalleryCase:
    for case in GALLERY:
        if case.name == name:
            return case
    raise KeyError(name)


def load_case(case: GalleryCase):
    from shadelab.scene.preset import load_preset

    return load_preset(case.preset, list(case.overrides))


def render_case(case: GalleryCase, size: tuple[int, int]) -> tuple[np.ndarray, float]:
    """The case's image (H, W, 3) float32 linear and the exposure to write it with."""
    from shadelab import pipelines

    scene = load_case(case)
    kind, _, variant = case.method.partition(":")
    options: dict = {}
    if kind == "raster":
        options = {"shading": variant or None}
    elif kind == "pathtrace":
        options = {"spp": int(variant or 16)}
    elif kind == "radiosity":
        options = {"adaptive": variant != "uniform", "gpu": True}
    try:
        pipeline = pipelines.get(kind)
    except Exception:
        raise ValueError(f"gallery case {case.name}: unknown method {case.method}") from None
    *_, last = pipeline.run(scene, None if kind == "radiosity" else size, **options)
    # radiosity: the CPU image of the solution (primary rays), as the gallery always drew it
    image = pipeline.image(last, size, display="cpu")
    return np.asarray(image, dtype=np.float32), scene.render.exposure
