"""Burn a legend of the current parameters into a viewport screenshot (PIL)."""

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
    """The (H, W, 3) uint8 image with the parameters written on a dark band at the bottom."""
    lines = legend_lines(state)
    pil = Image.fromarray(image)
    size = max(10, min(16, image.shape[0] // 40))
    try:
        font = ImageFont.load_default(size=size)
    except TypeError:  # Pillow < 10.1 has one bitmap size
        font = ImageFont.load_default()
    band = (size + 4) * len(lines) + 6
    draw = ImageDraw.Draw(pil, "RGBA")
    h = image.shape[0]
    draw.rectangle([0, h - band, image.shape[1], h], fill=(0, 0, 0, 170))
    for i, text in enumerate(lines):
        draw.text((6, h - band + 4 + i * (size + 4)), text, fill=(255, 255, 255, 255), font=font)
    return np.asarray(pil)
