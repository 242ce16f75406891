"""Pure scene data: camera, lights, materials, objects, presets. No GL, no GUI."""

from shadelab.scene.model import (  # noqa: F401
    Camera,
    Light,
    Material,
    Object,
    RadiositySettings,
    RaytraceSettings,
    RenderSettings,
    Scene,
)
from shadelab.scene.preset import list_presets, load_preset, save_preset  # noqa: F401
