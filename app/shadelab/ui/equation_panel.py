"""The Equation & probe window: the lighting equation and each of its terms at the probed
pixel (:func:`draw_equation_panel`)."""

from __future__ import annotations

import numpy as np
from imgui_bundle import imgui

from shadelab.lab.caption_terms import TERM_COLORS, TERM_LABELS, toggle_term
from shadelab.lab.state import AppState
from shadelab.shading.codes import TERMS
from shadelab.ui.layout import same_line_if_fits
from shadelab.ui.panels import (
    DIM_COLOR,
    ERROR_COLOR,
    OK_COLOR,
    SHADING_LABELS,
)

# ---------------------------------------------------------------- equation and probe


EQUATION = "I = Le + Ia ka Od + sum_i S_i f_att,i Ip,i [kd Od (N.L_i) + ks Os (R_i.V)^n]"
EQUATION_BLINN = "I = Le + Ia ka Od + sum_i S_i f_att,i Ip,i [kd Od (N.L_i) + ks Os (N.H_i)^n]"


def _rgb(v, digits: int = 3) -> str:
    """A 3-vector for reading: components below 1e-9 of its largest show as 0 (a unit normal
    reads (0, 0, 1), not (3.49e-17, -4.5e-16, 1))."""
    c = np.asarray(v, dtype=np.float64).reshape(-1)[:3]
    tiny = 1e-9 * max(float(np.abs(c).max()) if c.size else 0.0, 1e-300)
    return "(" + ", ".join(f"{0.0 if abs(x) < tiny else float(x):.{digits}g}" for x in c) + ")"


def _term_row(label: str, value, term: str | None = None) -> None:
    """A row of the terms table; ``term`` colours its label as the caption colours the term."""
    imgui.table_next_row()
    imgui.table_next_column()
    if term is not None:
        imgui.push_style_color(imgui.Col_.text, imgui.ImVec4(*TERM_COLORS[term]))
    imgui.text_wrapped(label)
    if term is not None:
        imgui.pop_style_color()
    values = np.asarray(value, dtype=np.float64).reshape(-1)
    for c in range(3):
        imgui.table_next_column()
        if c < len(values):
            v = values[c]  # tiny values short (e.g. 4.0e-66) so narrow columns show them
            imgui.text(f"{v:.4g}" if v == 0 or abs(v) >= 1e-3 else f"{v:.1e}")


def draw_term_switches(state: AppState) -> None:
    """One checkbox per term of the equation, in its colour: unticked, the term is left out of
    the viewport's image and the probe (the same switch as a click on the caption's term)."""
    imgui.text("Terms:")
    for term in TERMS:
        if same_line_if_fits(term, radio=True):
            imgui.same_line()
        imgui.push_style_color(imgui.Col_.text, imgui.ImVec4(*TERM_COLORS[term]))
        if imgui.checkbox(f"{term}##term", term not in state.view.terms_off)[0]:
            toggle_term(state, term)
        imgui.pop_style_color()
        imgui.set_item_tooltip(f"{TERM_LABELS[term]}: untick to leave it out of the image")


def draw_equation_panel(state: AppState) -> bool:
    """The lecture's equation with the current numbers, and the probed pixel's terms."""
    scene = state.scene
    blinn = scene.render.specular == "blinn"
    imgui.text_wrapped(EQUATION_BLINN if blinn else EQUATION)
    imgui.text_wrapped("f_att = min(1 / (c1 + c2 d + c3 d^2), 1);  "
                       + ("H = (L + V) / |L + V|" if blinn else "R = 2 N (N.L) - L"))
    imgui.text_wrapped(f"Ia = {_rgb(scene.Ia)}   shading: {SHADING_LABELS[scene.render.shading]}")
    draw_term_switches(state)
    result = state.probe.result
    if result is None:
        imgui.separator()
        imgui.text_wrapped("Click a pixel in the viewport to probe it: its N, L_i, V and "
                           + ("H_i" if blinn else "R_i") + " are drawn as arrows and every "
                           "term is listed here.")
        return False
    m = scene.materials[result.hit.mesh.material]
    imgui.separator()
    imgui.text_wrapped(f"pixel {result.pixel}  object {result.hit.mesh.index} "
               f"({scene.objects[result.hit.mesh.index].name or 'unnamed'}), material "
               f"'{result.hit.mesh.material}'")
    imgui.text_wrapped(f"P = {_rgb(result.point, 4)}  N = {_rgb(result.normal)}")
    imgui.text_wrapped(f"V = {_rgb(result.to_eye)}")
    imgui.text_wrapped(f"ka {m.ka:.3g}  kd {m.kd:.3g}  ks {m.ks:.3g}  n {m.n:.3g}  "
               f"Od {_rgb(m.Od)}  Os {_rgb(m.Os)}")
    imgui.push_text_wrap_pos(0.0)
    imgui.text_colored(DIM_COLOR, "arrows: N white, V cyan, L_i yellow, "
                       + ("H_i" if blinn else "R_i") + " magenta")
    imgui.pop_text_wrap_pos()
    lights = scene.active_lights()
    # Stretched to the panel's width (the term column wider): every column stays on screen
    # in a narrow presenter layout (1024x768), where fixed-fit columns pushed B off the edge.
    flags = (imgui.TableFlags_.borders | imgui.TableFlags_.row_bg
             | imgui.TableFlags_.sizing_stretch_prop)
    if imgui.begin_table("terms", 4, flags):
        for head, weight in (("term", 1.8), ("R", 1.0), ("G", 1.0), ("B", 1.0)):
            imgui.table_setup_column(head, imgui.TableColumnFlags_.width_stretch, weight)
        imgui.table_headers_row()
        terms = result.terms
        _term_row("Le (emission)", terms.emission)
        _term_row("ambient Ia ka Od", terms.ambient, "ambient")
        for i, t in enumerate(terms.lights[:len(lights)]):
            name = lights[i].name or f"light {i}"
            n_dot_l = float(np.dot(result.normal, t.to_light))
            spec_cos = float(np.dot(result.normal if blinn else result.reflected(i),
                                    result.reflected(i) if blinn else result.to_eye))
            _term_row(f"{name}: d, f_att", (float(t.distance), float(t.f_att)), "attenuation")
            shadow = np.asarray(t.shadow, dtype=np.float64).reshape(-1)
            if np.ptp(shadow) > 0.0:     # kt-filtered: one S_i per channel
                _term_row(f"{name}: S_i (r, g, b)", shadow, "shadow")
                _term_row(f"{name}: spot", float(t.spot))
            else:
                _term_row(f"{name}: S_i, spot", (float(shadow[0]), float(t.spot)), "shadow")
            _term_row(f"{name}: N.L, {'N.H' if blinn else 'R.V'}", (n_dot_l, spec_cos))
            _term_row(f"{name}: diffuse", t.diffuse, "diffuse")
            _term_row(f"{name}: specular", t.specular, "specular")
        if result.shading != "phong":
            _term_row("sum at this point", terms.total)
        _term_row(f"I ({result.shading} reference)", result.reference)
        if result.gpu is not None:
            _term_row("GPU drew", result.gpu)
        imgui.end_table()
    for i, t in enumerate(result.terms.lights[:len(lights)]):
        name = lights[i].name or f"light {i}"
        if lights[i].attenuation == "lecture":
            imgui.text_wrapped(f"{name}: min(1/(c1 + c2 d + c3 d^2), 1) clamp "
                       + ("ACTIVE (f_att = 1)" if bool(t.clamp_active) else "not active"))
        else:
            imgui.text_wrapped(f"{name}: attenuation '{lights[i].attenuation}' "
                               "(no min(., 1) clamp)")
    if result.gpu is not None:
        err = float(np.max(np.abs(result.gpu - result.reference)))
        agree = err <= 1e-4 * max(1.0, float(np.max(np.abs(result.reference))))
        imgui.push_text_wrap_pos(0.0)
        imgui.text_colored(OK_COLOR if agree else ERROR_COLOR,
                           f"GPU vs numpy reference: max |diff| {err:.2g} "
                           + ("(agree)" if agree else "(DIFFER)"))
        imgui.pop_text_wrap_pos()
    if result.shading != "phong":
        imgui.text_wrapped(f"{SHADING_LABELS[result.shading]} shading: the terms above are at "
                           "the probed point; the pixel's I is "
                           + ("the centroid's value." if result.shading == "flat"
                              else "the corners' values blended by barycentrics."))
    return False
