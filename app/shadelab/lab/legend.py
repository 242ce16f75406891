"""A legend of the current parameters in a margin under a viewport screenshot (PIL)."""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw, ImageFont

from shadelab.lab.state import AppState


def legend_lines(state: AppState) -> list[str]:
    scene = state.scene
    render = scene.render
    lines = [f"{scene.name or 'scene'}: {render.shading} shading, "
             f"{'Blinn-Phong' if render.specular == 'blinn' else 'Phong'} specular, "
             f"exposure {render.exposure:.3g}, Ia {tuple(round(c, 3) for c in scene.Ia)}"]
    if state.view.terms_off:   # the picture is not the whole equation: say which terms left
        from shadelab.shading.codes import TERMS

        lines[0] += ", terms off: " + ", ".join(t for t in TERMS if t in state.view.terms_off)
    for light in scene.active_lights():
        att = light.attenuation
        if att == "lecture":
            att = f"c1={light.c1:.3g} c2={light.c2:.3g} c3={light.c3:.3g}"
        lines.append(f"{light.name or light.kind}: {light.kind}, Ip "
                     f"{tuple(float(f'{c:.4g}') for c in light.Ip)}, f_att {att}")
    for name, m in list(scene.materials.items())[:4]:
        lines.append(f"{name}: ka {m.ka:.2g} kd {m.kd:.2g} ks {m.ks:.2g} n {m.n:.3g}")
    return lines


def burn_legend(image: np.ndarray, state: AppState) -> np.ndarray:
    """The (H, W, 3) uint8 image with the parameters written in a dark margin added under it
    ((H + margin, W, 3)): the legend never covers the picture."""
    lines = legend_lines(state)
    size = max(10, min(16, image.shape[0] // 40))
    try:
        font = ImageFont.load_default(size=size)
    except TypeError:  # Pillow < 10.1 has one bitmap size
        font = ImageFont.load_default()
    band = (size + 4) * len(lines) + 6
    h, w = image.shape[:2]
    pil = Image.new("RGB", (w, h + band), (16, 16, 16))
    pil.paste(Image.fromarray(image), (0, 0))
    draw = ImageDraw.Draw(pil)
    for i, text in enumerate(lines):
        draw.text((6, h + 4 + i * (size + 4)), text, fill=(255, 255, 255), font=font)
    return np.asarray(pil)
