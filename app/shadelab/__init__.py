"""ShadeLab: an interactive lab for illumination and shading.

The Python API (:mod:`shadelab.api`) is re-exported here and imported on first use
(PEP 562), so ``import shadelab`` loads no GL, GUI or numerics library::

    import shadelab
    scene = shadelab.load_preset("cornell")
    shadelab.render(scene, size=(256, 256), shading="phong").save("cornell.png")
"""

import sys
import types

__version__ = "0.1.0"

_API = ("PIPELINES", "Image", "ShadeLabError", "load_preset", "save_preset", "list_presets",
        "render", "probe", "show")

__all__ = ["__version__", *_API]


class _CallableRender(types.ModuleType):
    """``shadelab.render`` is both the raster subpackage and :func:`shadelab.api.render`."""

    def __call__(self, *args, **kwargs):
        from shadelab.api import render

        return render(*args, **kwargs)


class _Package(types.ModuleType):
    """The import system sets ``shadelab.render`` to the subpackage once it is imported;
    that module is made callable here, so ``shadelab.render(scene)`` always renders."""

    def __setattr__(self, name: str, value) -> None:
        if name == "render" and isinstance(value, types.ModuleType):
            value.__class__ = _CallableRender
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package


def __getattr__(name: str):
    if name == "render":  # the subpackage, made callable by _Package on import
        import importlib

        return importlib.import_module("shadelab.render")
    if name in _API:
        from shadelab import api

        return getattr(api, name)
    raise AttributeError(f"module 'shadelab' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*globals(), *_API])
