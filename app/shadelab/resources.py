"""Where shaders and presets live: inside the installed package, or at the repository root."""

from __future__ import annotations

from pathlib import Path

_PACKAGE_DIR = Path(__file__).resolve().parent


def resource_dir(name: str) -> Path:
    """Return the folder ``name`` ("shaders" or "presets"): the one way every module finds
    them (``gl/programs.py``, ``testing.py``, ``scene/preset.py``).

    A wheel ships them inside the package (``shadelab/shaders``, pyproject's force-include); a
    checkout keeps them at the repository root, beside ``app/`` (the package itself is
    ``app/shadelab``). tests/shading/test_shader_dir.py checks both layouts.
    """
    for candidate in (_PACKAGE_DIR / name, _PACKAGE_DIR.parent.parent / name):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(f"ShadeLab resource folder '{name}' is missing from the installation")


def shaders_dir() -> Path:
    return resource_dir("shaders")


def presets_dir() -> Path:
    return resource_dir("presets")
