"""Load GLSL programs from ``shaders/``: one file per stage, chunks from ``shaders/include``.

Chunks are registered as moderngl named includes (``#include "lighting"``).
"""

from __future__ import annotations

import moderngl

from app.resources import shaders_dir


def register_includes(ctx: moderngl.Context) -> None:
    for path in sorted((shaders_dir() / "include").glob("*.glsl")):
        ctx.includes[path.stem] = path.read_text(encoding="utf-8")


def load_program(ctx: moderngl.Context, name: str) -> moderngl.Program:
    """Compile ``shaders/<name>.vert`` and ``<name>.frag`` (and ``<name>.geom`` if present)."""
    register_includes(ctx)
    folder = shaders_dir()
    sources = {"vertex_shader": (folder / f"{name}.vert").read_text(encoding="utf-8"),
               "fragment_shader": (folder / f"{name}.frag").read_text(encoding="utf-8")}
    geometry = folder / f"{name}.geom"
    if geometry.is_file():
        sources["geometry_shader"] = geometry.read_text(encoding="utf-8")
    return ctx.program(**sources)


def set_uniform(program: moderngl.Program, name: str, value) -> None:
    """Set a uniform if the compiler kept it (unused uniforms are optimized away)."""
    if name not in program:
        return
    uniform = program[name]
    if isinstance(value, (bytes, bytearray)):
        uniform.write(value)
    else:
        uniform.value = value


def set_uniform_array(program: moderngl.Program, name: str, array) -> None:
    """Write a uniform array; the compiler may have trimmed unused trailing elements."""
    if name not in program:
        return
    uniform = program[name]
    count = max(uniform.array_length, 1)
    uniform.write(array[:count].tobytes())
