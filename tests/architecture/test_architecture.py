"""Pure layers import no GL or GUI library (ARCHITECTURE.md §1), checked in a fresh interpreter."""

from __future__ import annotations

import subprocess
import sys

import pytest

PURE = ["shadelab.scene", "shadelab.scene.preset", "shadelab.scene.camera", "shadelab.shading",
        "shadelab.shading.reference", "shadelab.geometry.mesh", "shadelab.geometry.normals",
        "shadelab.progress", "shadelab.exercises"]
OPTIONAL_PURE = ["shadelab.raytrace", "shadelab.radiosity", "shadelab.geometry.silhouette"]
FORBIDDEN = ("moderngl", "glfw", "imgui_bundle", "OpenGL")


@pytest.mark.parametrize("module", PURE + OPTIONAL_PURE)
def test_pure_module_imports_no_gl(module):
    code = (f"import importlib, sys\n"
            f"try:\n    importlib.import_module({module!r})\n"
            f"except ModuleNotFoundError as e:\n"
            f"    if e.name == {module!r}: print('MISSING'); raise SystemExit(0)\n    raise\n"
            f"print(sorted(m for m in sys.modules if m.split('.')[0] in {FORBIDDEN!r}))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    if "MISSING" in out.stdout and module in OPTIONAL_PURE:
        pytest.skip(f"{module} not built")
    assert out.stdout.strip() == "[]", out.stdout
