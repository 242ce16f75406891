"""Pure scene data: camera, lights, materials, objects, presets. No GL, no GUI."""

from shadelab.scene import model as _model
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
from shadelab.scene.preset import _check as _preset_check
from shadelab.scene.preset import list_presets, load_preset, save_preset  # noqa: F401

_model._VALIDATE = _preset_check  # Checked assignments are validated as preset values are
