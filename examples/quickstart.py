"""ShadeLab from a script: load a preset, change it in code, render, probe, compare.

Run:  python examples/quickstart.py [OUT_DIR]     (headless: no window is opened)
"""

import sys
from pathlib import Path

import numpy as np

import shadelab

out = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
out.mkdir(parents=True, exist_ok=True)

# 1. A preset, with overrides validated exactly as the CLI's --set.
scene = shadelab.load_preset("cornell", overrides={"materials.white.kd": 0.9})

# 2. Edit in code: every assignment is checked against the preset schema.
scene.materials["red"].kd = 0.8
try:
    scene.materials["red"].kd = 1.5          # out of [0, 1]: refused, kd stays 0.8
except shadelab.ShadeLabError as exc:
    print("refused:", exc)

# 3. One image per shading mode: float32 linear radiance (H, W, 3).
images = {mode: shadelab.render(scene, size=(160, 160), shading=mode)
          for mode in ("flat", "gouraud", "phong")}
for mode, image in images.items():
    image.save(out / f"cornell_{mode}.png")   # sRGB PNG (Jupyter shows `image` inline)
    print(f"{mode:8s} mean radiance {image.array.mean():.4f}")

# 4. The probe: the lecture's terms at one pixel, as plain data.
terms = shadelab.probe(scene, (40, 100), size=(160, 160), shading="phong")
print("object", terms["object"], "material", terms["material"])
print("ambient", np.round(terms["ambient"], 4), "diffuse",
      np.round(terms["lights"][0]["diffuse"], 4), "total", np.round(terms["total"], 4))

# 5. Another pipeline on the same scene, pixel-aligned with the raster image.
traced = shadelab.render(scene, size=(160, 160), pipeline="raytrace", depth=2)
diff = np.abs(traced.array - images["phong"].array).mean()
print(f"raytrace vs phong raster: mean |difference| {diff:.4f}")
traced.save(out / "cornell_raytrace.png")
