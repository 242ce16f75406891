"""ShadeLab: an interactive lab for illumination and shading.

The Python API (:mod:`shadelab.api`) is re-exported here and imported on first use
(PEP 562), so ``import shadelab`` loads no GL, GUI or numerics library::

    import shadelab
    scene = shadelab.load_preset("cornell")
    shadelab.render(scene, size=(256, 256), shading="phong").save("cornell.png")
"""

from shadelab.paths import configure_numba_cache as _configure_numba_cache
from shadelab.version import __version__  # one place: version.py

# numba's kernel cache goes to the user's cache folder, set before any kernel module imports
# numba (the one place; see shadelab.paths)
_configure_numba_cache()

_API = ("PIPELINES", "Image", "ShadeLabError", "load_preset", "save_preset", "list_presets",
        "render", "probe", "show")

__all__ = ["__version__", *_API]


def __getattr__(name: str):
    if name in _API:
        from shadelab import api

        value = getattr(api, name)
        globals()[name] = value  # the real function: help() and inspect.signature see it
        return value
    raise AttributeError(f"module 'shadelab' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted([*globals(), *_API])
