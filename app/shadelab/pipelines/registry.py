"""The one list of pipelines: :func:`register`, :func:`get`, :func:`names`.

The built-in pipelines (one module each in this package) register themselves when first asked
for; another module or a test registers its own with ``@register`` (a class or an instance).
Pure: importing this module imports no pipeline's renderer.
"""

from __future__ import annotations

import importlib
from contextlib import contextmanager

from shadelab.errors import ShadeLabError

#: The built-in pipelines' modules, in the order the registry lists them.
BUILTIN_MODULES = ("painter", "raster", "radiosity", "raytrace", "pathtrace", "reference")
#: Old names that keep working: ``raster`` is the GL z-buffer with the scene's own shading.
ALIASES = {"raster": "raster"}

_REGISTRY: dict = {}
_BUILTIN: set[str] = set()
_loading = False
_loaded = False


def _load_builtins() -> None:
    global _loading, _loaded
    if _loaded or _loading:
        return
    _loading = True
    try:
        for module in BUILTIN_MODULES:
            before = set(_REGISTRY)
            importlib.import_module(f"shadelab.pipelines.{module}")
            _BUILTIN.update(set(_REGISTRY) - before)
        # list the built-ins in BUILTIN_MODULES order (painter's module imports raster's)
        def rank(item):
            module = type(item[1]).__module__.rsplit(".", 1)[-1]
            return BUILTIN_MODULES.index(module) if module in BUILTIN_MODULES else 99
        ordered = sorted((kv for kv in _REGISTRY.items() if kv[0] in _BUILTIN), key=rank)
        others = [kv for kv in _REGISTRY.items() if kv[0] not in _BUILTIN]
        _REGISTRY.clear()
        _REGISTRY.update(ordered + others)
        _loaded = True
    finally:
        _loading = False


def register(pipeline):
    """Add a pipeline (an instance, or a class made with no arguments); returns it, so it
    works as a class decorator. A name registered twice replaces the first."""
    instance = pipeline() if isinstance(pipeline, type) else pipeline
    name = getattr(instance, "name", "")
    if not name or not isinstance(name, str):
        raise ShadeLabError(f"pipeline {instance!r}: expected a non-empty name")
    for attr in ("label", "output", "run", "check"):
        if not hasattr(instance, attr):
            raise ShadeLabError(f"pipeline '{name}': has no {attr}")
    _REGISTRY[name] = instance
    if type(instance).__module__.rsplit(".", 1)[0] == __package__:
        _BUILTIN.add(name)  # a module of this package (imported directly or by the loader)
    return pipeline


def unregister(name: str) -> None:
    _REGISTRY.pop(name, None)
    _BUILTIN.discard(name)


@contextmanager
def registered(pipeline):
    """``with registered(MyPipeline()):`` (tests): registered inside the block only."""
    instance = pipeline() if isinstance(pipeline, type) else pipeline
    _load_builtins()
    previous = _REGISTRY.get(instance.name)
    register(instance)
    try:
        yield instance
    finally:
        unregister(instance.name)
        if previous is not None:
            _REGISTRY[instance.name] = previous
            _BUILTIN.add(instance.name)


def names() -> tuple[str, ...]:
    """Every registered pipeline's name (aliases not included), built-ins first."""
    _load_builtins()
    return tuple(name for name in _REGISTRY if name not in ALIASES)


def all_names() -> tuple[str, ...]:
    """What ``shadelab.render(pipeline=...)`` accepts: the aliases, then :func:`names`."""
    _load_builtins()
    return tuple(ALIASES) + names()


def get(name: str, what: str = "pipeline"):
    """The pipeline called ``name`` (or an alias); ShadeLabError naming the choices."""
    _load_builtins()
    pipeline = _REGISTRY.get(ALIASES.get(name, name)) if isinstance(name, str) else None
    if pipeline is None:
        raise ShadeLabError(f"{what} '{name}': expected one of {', '.join(all_names())}")
    return pipeline


def is_builtin(name: str) -> bool:
    return name in _BUILTIN


def pipelines() -> list:
    """The registered pipeline objects, in :func:`names` order."""
    return [_REGISTRY[name] for name in names()]


def viewport_names() -> tuple[str, ...]:
    """The viewer's Pipeline selector, in its order."""
    return tuple(p.name for p in sorted((p for p in pipelines() if p.viewport),
                                        key=lambda p: p.viewport))


def job_pipelines() -> list:
    """The Offline panel's renderers, in its order."""
    return sorted((p for p in pipelines() if p.job_label), key=lambda p: p.job_order)
