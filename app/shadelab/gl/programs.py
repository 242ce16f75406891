"""Load GLSL programs from ``shaders/``: one file per stage, chunks from ``shaders/include``.

Chunks are registered as moderngl named includes (``#include "lighting"``). The lighting
chunk starts with ``#define``s generated from the Python table of codes and constants
(:func:`shadelab.shading.codes.glsl_header`: ``LIGHT_SPOT``, ``ATTENUATION_LECTURE``,
``SHADING_EPS`` ...), so the GLSL holds no hand-written copy of them.
"""

from __future__ import annotations

import moderngl

from shadelab.resources import shaders_dir
from shadelab.shading import codes, conventions

# Generated text put at the head of an include (moderngl includes do not nest)
GENERATED_HEADERS = {"lighting": codes.glsl_header, "color": conventions.glsl_header}


def register_includes(ctx: moderngl.Context) -> None:
    for path in sorted((shaders_dir() / "include").glob("*.glsl")):
        header = GENERATED_HEADERS.get(path.stem)
        text = path.read_text(encoding="utf-8")
        ctx.includes[path.stem] = (header() if header else "") + text


def stock_include(ctx: moderngl.Context, name: str) -> bool:
    """Whether the context's include ``name`` is ShadeLab's own text (not a replacement, as
    :func:`shadelab.testing.render_with_shaders` puts there for a student's chunk)."""
    path = shaders_dir() / "include" / f"{name}.glsl"
    header = GENERATED_HEADERS.get(name)
    stock = (header() if header else "") + path.read_text(encoding="utf-8")
    return ctx.includes.get(name) == stock


def with_defines(source: str, defines: dict[str, object] | None) -> str:
    """Insert ``#define NAME VALUE`` lines right after the ``#version`` line."""
    if not defines:
        return source
    first, _, rest = source.partition("\n")
    lines = "".join(f"#define {key} {value}\n" for key, value in defines.items())
    return f"{first}\n{lines}{rest}"


def load_program(ctx: moderngl.Context, name: str,
                 defines: dict[str, object] | None = None) -> moderngl.Program:
    """Compile ``shaders/<name>.vert`` and ``<name>.frag`` (and ``<name>.geom`` if present),
    with optional ``#define``s (e.g. ``NUM_LIGHTS``) inserted in every stage."""
    register_includes(ctx)
    folder = shaders_dir()
    stages = {"vertex_shader": "vert", "fragment_shader": "frag", "geometry_shader": "geom"}
    sources = {}
    for stage, suffix in stages.items():
        path = folder / f"{name}.{suffix}"
        if path.is_file():
            sources[stage] = with_defines(path.read_text(encoding="utf-8"), defines)
    return ctx.program(**sources)


def set_uniform(program: moderngl.Program, name: str, value) -> None:
    """Set a uniform if the compiler kept it (unused uniforms are optimized away)."""
    uniform = program.get(name, None)  # a dict look-up; ``name in program`` scans every member
    if uniform is None:
        return
    if isinstance(value, (bytes, bytearray)):
        uniform.write(value)
    else:
        uniform.value = value


def set_uniform_array(program: moderngl.Program, name: str, array) -> None:
    """Write a uniform array; the compiler may have trimmed unused trailing elements."""
    uniform = program.get(name, None)
    if uniform is None:
        return
    count = max(uniform.array_length, 1)
    uniform.write(array[:count].tobytes())


class UniformCache:
    """A program's uniforms written only when their bytes change (one dict look-up and one
    bytes comparison per uniform per frame; a GL write only for what moved).

    Every write to a cached program must go through :meth:`write` or :meth:`write_array`;
    :meth:`forget` drops the record after a write that bypassed it.
    """

    def __init__(self, program: moderngl.Program):
        self.program = program
        self._uniforms = {name: program[name] for name in program
                          if isinstance(program[name], moderngl.Uniform)}
        self._last: dict[str, bytes] = {}

    def __contains__(self, name: str) -> bool:
        return name in self._uniforms

    def write(self, name: str, data: bytes) -> None:
        """Write ``data`` (the uniform's packed bytes) unless it is what the GL holds."""
        uniform = self._uniforms.get(name)
        if uniform is None or self._last.get(name) == data:
            return
        uniform.write(data)
        self._last[name] = data

    def write_array(self, name: str, array) -> None:
        """Write a uniform array trimmed to the elements the compiler kept."""
        uniform = self._uniforms.get(name)
        if uniform is not None:
            self.write(name, array[:max(uniform.array_length, 1)].tobytes())

    def forget(self, name: str | None = None) -> None:
        if name is None:
            self._last.clear()
        else:
            self._last.pop(name, None)
