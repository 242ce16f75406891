"""TOML presets: load, validate, override with ``--set``, save (round-trips exactly).

Every error is a :class:`ShadeLabError` whose one line names the file, the key (or line)
and what was expected.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import os
import reprlib
import tomllib
from pathlib import Path
from typing import Any

import tomli_w

from shadelab import limits
from shadelab.errors import ShadeLabError
from shadelab.paths import (
    OutputSet,
    clobber_problem,
    file_problem,
    output_problem,
    resolve_link,
)
from shadelab.progress import steps
from shadelab.resources import presets_dir
from shadelab.scene.model import (
    AIMED_LIGHT_KINDS,
    MAX_LIGHTS,
    SCHEMA_VERSION,
    Camera,
    Light,
    Material,
    Object,
    RadiositySettings,
    RaytraceSettings,
    RenderSettings,
    Scene,
)

MAX_PRESET_BYTES = 64 * 1024 * 1024  # a preset is text a person edits; 64 MiB is generous
MAX_NESTING = 8  # deepest valid key: objects.N.vertices.M (4 levels); room for mistakes

_SECTIONS = {
    "camera": Camera,
    "render": RenderSettings,
    "raytrace": RaytraceSettings,
    "radiosity": RadiositySettings,
}


# ---------------------------------------------------------------- finding presets


def list_presets() -> list[str]:
    """Names of the presets shipped with ShadeLab, sorted."""
    return sorted(p.stem for p in presets_dir().glob("*.toml"))


def resolve_preset(name_or_path: str) -> Path:
    """A preset name from ``presets/`` or a path to a TOML file."""
    path = Path(name_or_path)
    if path.suffix == ".toml" or path.exists() or "/" in name_or_path:
        if not path.is_file():
            raise ShadeLabError(f"{name_or_path}: preset file not found")
        return path
    candidate = presets_dir() / f"{name_or_path}.toml"
    if not candidate.is_file():
        names = ", ".join(list_presets())
        raise ShadeLabError(f"unknown preset '{name_or_path}' "
                            f"(expected one of: {names}, or a path)")
    return candidate


# ---------------------------------------------------------------- loading


def load_preset(name_or_path: str, overrides: list[str] | None = None) -> Scene:
    """Load, override and validate a preset; the result is a :class:`Scene`."""
    path = resolve_preset(name_or_path)
    raw = read_toml(path)
    for item in overrides or []:
        apply_override(raw, item, str(path))
    scene = scene_from_dict(raw, str(path))
    scene.name = path.stem
    scene.base_dir = str(path.resolve().parent)
    check_files(scene, str(path))
    from shadelab.geometry.mesh import adopt_obj_materials  # an OBJ's MTL: Kd, map_Kd

    tables = raw.get("materials") if isinstance(raw.get("materials"), dict) else {}
    adopt_obj_materials(scene, {name: set(t) for name, t in tables.items()
                                if isinstance(t, dict)}, str(path))
    return scene


def scene_inputs(scene: Scene, preset: str | Path | None = None) -> list[tuple[str, Path]]:
    """(what, file) of every file a scene was read from: its preset (a name or a path), mesh,
    texture and bump files (what :func:`shadelab.paths.check_output` keeps from being
    overwritten)."""
    files: list[tuple[str, Path]] = []
    if preset:
        try:
            files.append(("input preset", resolve_preset(str(preset))))
        except ShadeLabError:
            pass
    base = Path(scene.base_dir)

    def add(what: str, value: str) -> None:
        files.append((what, Path(value) if Path(value).is_absolute() else base / value))
    for obj in scene.objects:
        if obj.shape == "mesh" and obj.path:
            add("mesh", obj.path)
            if Path(obj.path).suffix.lower() == ".obj":  # its MTL and the MTL's textures
                mtl = (Path(obj.path) if Path(obj.path).is_absolute() else base / obj.path)
                files.extend(("mesh", p) for p in mtl.parent.glob("*.mtl"))
    for m in scene.materials.values():
        if m.texture and m.texture != "checker":
            add("texture", m.texture)
        if m.bump and m.bump != "bumps":
            add("bump map", m.bump)
    return files


def check_files(scene: Scene, source: str) -> None:
    """Every mesh and image file the scene names is a readable regular file (no folder, FIFO,
    symlink loop or too-long name); read later, it cannot fail for want of the file."""
    base = Path(scene.base_dir)
    named = [(f"objects.{i}.path", obj.path) for i, obj in enumerate(scene.objects)
             if obj.shape == "mesh" and obj.path]
    for name, m in scene.materials.items():
        if m.texture and m.texture != "checker":
            named.append((f"materials.{name}.texture", m.texture))
        if m.bump and m.bump != "bumps":
            named.append((f"materials.{name}.bump", m.bump))
    for key, value in named:
        problem = file_problem(Path(value) if Path(value).is_absolute() else base / value)
        if problem:
            raise ShadeLabError(f"{source}: key '{key}': file '{value}' {problem}")


def read_toml(path: Path) -> dict:
    try:
        size = path.stat().st_size
        if size > MAX_PRESET_BYTES:
            raise ShadeLabError(f"{path}: preset is {size / 2**20:.0f} MiB, expected a TOML "
                                f"text under {MAX_PRESET_BYTES // 2**20} MiB")
        data = path.read_bytes()
    except OSError as exc:
        raise ShadeLabError(f"{path}: cannot read preset ({exc.strerror})") from None
    return parse_toml(decode_text(data, str(path), "preset"), str(path))


def decode_text(data: bytes, source: str, what: str = "file") -> str:
    """UTF-8 text (a UTF-8 byte-order mark is allowed) or a one-line error saying what it is."""
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise ShadeLabError(f"{source}: {what} is UTF-16 text; save it as UTF-8")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        column = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        raise ShadeLabError(f"{source}: {what} is not UTF-8 text (byte 0x{data[exc.start]:02x} "
                            f"at line {line}, column {column}); save it as UTF-8") from None
    if "\x00" in text:
        raise ShadeLabError(f"{source}: {what} is binary data, expected TOML text")
    return text


def parse_toml(text: str, source: str) -> dict:
    """tomllib, with its recursion on deep nesting and any nesting past MAX_NESTING refused."""
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ShadeLabError(f"{source}: TOML syntax error: {exc}") from None
    except RecursionError:
        raise ShadeLabError(f"{source}: arrays or tables nested too deeply "
                            f"(expected at most {MAX_NESTING} levels)") from None
    _check_nesting(raw, source)
    return raw


def _check_nesting(value: Any, source: str, limit: int = MAX_NESTING) -> None:
    """Refuse containers nested deeper than ``limit`` (iterative: no recursion to exhaust)."""
    stack = [(value, 0, "")]
    while stack:
        node, depth, where = stack.pop()
        if depth > limit:
            raise ShadeLabError(f"{source}: key '{where}': arrays or tables nested too deeply "
                                f"(expected at most {limit} levels)")
        if isinstance(node, dict):
            stack.extend((v, depth + 1, f"{where}.{k}" if where else str(k))
                         for k, v in node.items())
        elif isinstance(node, list):
            stack.extend((v, depth + 1, f"{where}.{i}" if where else str(i))
                         for i, v in enumerate(node))


_REPR = reprlib.Repr()
_REPR.maxlevel, _REPR.maxlist, _REPR.maxstring, _REPR.maxother = 3, 6, 60, 60
_REPR.maxdict = 4


def _show(value: Any) -> str:
    """A short repr for messages: a huge or deep value does not make a huge line."""
    return _REPR.repr(value)


def scene_from_dict(raw: dict, source: str = "<preset>") -> Scene:
    """Validate a preset dictionary into a Scene; unknown keys are errors."""
    if not isinstance(raw, dict):
        raise ShadeLabError(f"{source}: expected a table at the top level")
    data = dict(raw)
    version = data.pop("schema_version", None)
    if version != SCHEMA_VERSION:
        raise ShadeLabError(
            f"{source}: key 'schema_version': expected {SCHEMA_VERSION}, got {version!r}")
    scene = Scene()
    for key, value in data.items():
        if key in _SECTIONS:
            setattr(scene, key, _build(_SECTIONS[key], value, source, key))
        elif key == "lights":
            scene.lights = [_build(Light, item, source, f"lights.{i}")
                            for i, item in enumerate(_as_list(value, source, key))]
        elif key == "objects":
            items = _as_list(value, source, key)
            scene.objects = [_build(Object, item, source, f"objects.{i}")
                             for i, item in steps(enumerate(items), len(items),
                                                  "validating objects")]
        elif key == "materials":
            if not isinstance(value, dict):
                raise ShadeLabError(f"{source}: key 'materials': expected a table of materials")
            scene.materials = {name: _build(Material, item, source, f"materials.{name}")
                               for name, item in value.items()}
        elif key in ("description", "Ia"):
            setattr(scene, key, _check(Scene, key, value, source, key))
        else:
            raise ShadeLabError(f"{source}: unknown key '{key}' (expected one of: "
                                f"schema_version, description, Ia, camera, lights, materials, "
                                f"objects, render, raytrace, radiosity)")
    _cross_check(scene, source)
    return scene


def _as_list(value: Any, source: str, key: str) -> list:
    if not isinstance(value, list):
        raise ShadeLabError(f"{source}: key '{key}': expected an array of tables")
    return value


def _build(cls: type, value: Any, source: str, where: str):
    if not isinstance(value, dict):
        raise ShadeLabError(f"{source}: key '{where}': expected a table")
    names = {f.name for f in dataclasses.fields(cls) if "spec" in f.metadata}
    obj = cls()
    for key, item in value.items():
        if key not in names:
            raise ShadeLabError(f"{source}: unknown key '{where}.{key}' "
                                f"(expected one of: {', '.join(sorted(names))})")
        setattr(obj, key, _check(cls, key, item, source, f"{where}.{key}"))
    return obj


def _field_spec(cls: type, key: str) -> tuple:
    for f in dataclasses.fields(cls):
        if f.name == key:
            return f.metadata["spec"]
    raise KeyError(key)


def _number(value: Any, source: str, where: str, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ShadeLabError(f"{source}: key '{where}': expected {what}, got {_show(value)}")
    try:
        out = float(value)  # an integer past 1.8e308 overflows here
    except OverflowError:
        out = math.inf
    if not math.isfinite(out):
        raise ShadeLabError(f"{source}: key '{where}': expected {what}, "
                            f"got {_show(value)} (not finite)")
    return out


def _vec3(value: Any, source: str, where: str, what: str, lo: float, hi: float):
    if not isinstance(value, (list, tuple)) or len(value) != 3:
        raise ShadeLabError(f"{source}: key '{where}': expected {what}, got {_show(value)}")
    out = tuple(_number(v, source, where, what) for v in value)
    if min(out) < lo or max(out) > hi:
        raise ShadeLabError(f"{source}: key '{where}': expected {what}, got {_show(value)}")
    return out


def _check(cls: type, key: str, value: Any, source: str, where: str) -> Any:
    """Validate one value against its field spec and return it in canonical form."""
    kind, *args = _field_spec(cls, key)
    if kind == "float":
        lo, hi = args
        what = f"a number in [{lo:g}, {hi:g}]"
        out = _number(value, source, where, what)
        if not lo <= out <= hi:
            raise ShadeLabError(f"{source}: key '{where}': expected {what}, got {_show(value)}")
        return out
    if kind == "int":
        lo, hi = args
        what = f"an integer in [{lo}, {hi}]"
        if isinstance(value, bool) or not isinstance(value, int) or not lo <= value <= hi:
            raise ShadeLabError(f"{source}: key '{where}': expected {what}, got {_show(value)}")
        return int(value)
    if kind == "bool":
        if not isinstance(value, bool):
            raise ShadeLabError(f"{source}: key '{where}': expected true or false, "
                                f"got {_show(value)}")
        return value
    if kind == "str":
        (choices,) = args
        if not isinstance(value, str) or (choices and value not in choices):
            expected = " | ".join(choices) if choices else "a string"
            raise ShadeLabError(f"{source}: key '{where}': expected {expected}, got {_show(value)}")
        return value
    if kind == "rgb":
        (hi,) = args
        return _vec3(value, source, where, f"three numbers in [0, {hi:g}] (linear RGB)", 0.0, hi)
    if kind == "rgb01":
        return _vec3(value, source, where, "three numbers in [0, 1] (a reflectance color)",
                     0.0, 1.0)
    if kind == "vec3":
        lo, hi = args
        return _vec3(value, source, where, f"three numbers in [{lo:g}, {hi:g}]", lo, hi)
    if kind == "vec3s":
        lo, hi = args
        what = f"a list of [x, y, z] points, each number in [{lo:g}, {hi:g}]"
        if not isinstance(value, list):
            raise ShadeLabError(f"{source}: key '{where}': expected {what}")
        return [_vec3(v, source, where, what, lo, hi) for v in value]
    raise AssertionError(kind)


def estimated_triangles(obj: Object) -> int:
    """Triangles a primitive will have (closed form, before meshing); 0 for mesh files,
    whose count is checked when they are read."""
    sec = obj.sections
    return {"sphere": 20 * 4 ** obj.subdivisions, "box": 12, "cylinder": 4 * sec,
            "cone": 2 * sec, "capsule": 2 * sec * sec, "torus": 2 * sec * max(sec // 2, 3),
            "plane": 2 * obj.segments ** 2, "quad": 2 * obj.segments ** 2}.get(obj.shape, 0)


def check_scene(scene: Scene, source: str = "scene") -> None:
    """What a preset would refuse, for a scene edited in Python: its parts of the right kinds
    (fields are validated at assignment) and the cross-table checks of :func:`_cross_check`
    (material names, quad vertices, scales, light count and directions, camera)."""
    from shadelab.scene.model import Camera, Material

    parts = (("lights", list, Light), ("objects", list, Object))
    for key, container, item in parts:
        value = getattr(scene, key)
        if not isinstance(value, container):
            raise ShadeLabError(f"{source}: key '{key}': expected a list of {item.__name__}, "
                                f"got {type(value).__name__}")
        for i, entry in enumerate(value):
            if not isinstance(entry, item):
                raise ShadeLabError(f"{source}: key '{key}.{i}': expected a {item.__name__}, "
                                    f"got {type(entry).__name__}")
    if not isinstance(scene.materials, dict) or not all(
            isinstance(k, str) and isinstance(v, Material) for k, v in scene.materials.items()):
        raise ShadeLabError(f"{source}: key 'materials': expected a dict of name -> Material")
    if not isinstance(scene.camera, Camera):
        raise ShadeLabError(f"{source}: key 'camera': expected a Camera, "
                            f"got {type(scene.camera).__name__}")
    _cross_check(scene, source)


def _cross_check(scene: Scene, source: str) -> None:
    """Checks that span tables: material references, required shape keys, light count."""
    limits.check(f"{source}: key 'objects'", len(scene.objects), limits.MAX_OBJECTS, "objects")
    limits.check(f"{source}: key 'objects' (primitives)",
                 sum(estimated_triangles(obj) for obj in scene.objects), limits.MAX_TRIANGLES,
                 "triangles")
    if len(scene.lights) > MAX_LIGHTS:
        raise ShadeLabError(f"{source}: key 'lights': at most {MAX_LIGHTS} lights, "
                            f"got {len(scene.lights)}")
    for i, obj in enumerate(scene.objects):
        if obj.material not in scene.materials:
            if obj.material == "default":
                scene.materials.setdefault("default", Material())
            else:
                names = ", ".join(scene.materials) or "none defined"
                raise ShadeLabError(f"{source}: key 'objects.{i}.material': expected a material "
                                    f"name ({names}), got '{obj.material}'")
        if obj.shape == "quad" and len(obj.vertices) != 4:
            raise ShadeLabError(f"{source}: key 'objects.{i}.vertices': expected 4 points "
                                f"for a quad, got {len(obj.vertices)}")
        if obj.shape == "mesh" and not obj.path:
            raise ShadeLabError(f"{source}: key 'objects.{i}.path': expected a mesh file path")
        if min(abs(s) for s in obj.scale) == 0.0:
            raise ShadeLabError(f"{source}: key 'objects.{i}.scale': expected non-zero scales")
    for i, light in enumerate(scene.lights):
        if light.kind in AIMED_LIGHT_KINDS and sum(d * d for d in light.direction) == 0.0:
            raise ShadeLabError(f"{source}: key 'lights.{i}.direction': expected a non-zero vector")
        if light.attenuation == "lecture" and light.c1 + light.c2 + light.c3 == 0.0:
            # f_att = min(1/0, 1) = 1: allowed, the clamp makes it finite (failure gallery)
            pass
    cam = scene.camera
    if sum((a - b) ** 2 for a, b in zip(cam.eye, cam.target, strict=True)) == 0.0:
        raise ShadeLabError(f"{source}: key 'camera.target': expected a point other than the eye")


# ---------------------------------------------------------------- --set overrides


def parse_value(text: str) -> Any:
    """Parse a ``--set`` value: TOML scalars, ``a,b,c`` lists, or a bare string."""
    text = text.strip()
    if "," in text and not text.startswith("["):
        return [parse_value(part) for part in text.split(",")]
    try:
        value = tomllib.loads(f"v = {text}")["v"]
    except RecursionError:
        raise ShadeLabError(f"--set value '{text[:40]}...': arrays or tables nested too deeply "
                            f"(expected at most {MAX_NESTING} levels)") from None
    except tomllib.TOMLDecodeError:
        lowered = text.lower()
        if lowered in ("nan", "+nan", "-nan", "inf", "+inf", "-inf"):
            return float(lowered)
        return text
    _check_nesting(value, "--set value")
    return value


def apply_override(raw: dict, item: str, source: str = "--set") -> None:
    """Apply ``KEY=VALUE`` to a preset dictionary; ``lights.0.Ip=2,2,2`` indexes arrays."""
    if "=" not in item:
        raise ShadeLabError(f"--set '{item}': expected KEY=VALUE, e.g. materials.white.kd=0.5")
    key, value = item.split("=", 1)
    parts = key.strip().split(".")
    node: Any = raw
    for depth, part in enumerate(parts[:-1]):
        node = _descend(node, part, parts[: depth + 1], source)
    last = parts[-1]
    if isinstance(node, list):
        index = _index(node, last, parts, source)
        node[index] = parse_value(value)
    elif isinstance(node, dict):
        node[last] = parse_value(value)
    else:
        raise ShadeLabError(f"--set '{key}': '{'.'.join(parts[:-1])}' is not a table")


def _descend(node: Any, part: str, path: list[str], source: str) -> Any:
    dotted = ".".join(path)
    if isinstance(node, list):
        return node[_index(node, part, path, source)]
    if isinstance(node, dict):
        if part not in node:
            if path[0] in _SECTIONS and len(path) == 1:
                node[part] = {}
            else:
                raise ShadeLabError(f"--set '{dotted}': no such key in {source}")
        return node[part]
    raise ShadeLabError(f"--set '{dotted}': not a table or an array")


def _index(node: list, part: str, path: list[str], source: str) -> int:
    if not (part.isascii() and part.isdigit()) or int(part) >= len(node):
        raise ShadeLabError(f"--set '{'.'.join(path)}': expected an index below {len(node)} "
                            f"in {source}")
    return int(part)


# ---------------------------------------------------------------- saving


def scene_to_dict(scene: Scene) -> dict:
    """The preset dictionary of a scene: every field written, so a reload is exact."""

    def table(obj) -> dict:
        out = {}
        for f in dataclasses.fields(obj):
            if "spec" not in f.metadata:
                continue
            value = getattr(obj, f.name)
            if isinstance(value, tuple):
                value = list(value)
            if f.name == "vertices":
                value = [list(v) for v in value]
            out[f.name] = value
        return out

    data: dict[str, Any] = {"schema_version": SCHEMA_VERSION, "description": scene.description,
                            "Ia": list(scene.Ia)}
    for key in _SECTIONS:
        data[key] = table(getattr(scene, key))
    data["materials"] = {name: table(m) for name, m in scene.materials.items()}
    data["lights"] = [table(light) for light in scene.lights]
    data["objects"] = [table(obj) for obj in scene.objects]
    return data


def save_preset(scene: Scene, path: str | Path) -> None:
    """Write the scene as a TOML preset, all or nothing (a unique temporary file, fsync,
    rename). A read-only file is refused, not replaced; a symlink is written through (the
    shared target changes, the link stays). Relative mesh and image paths are rebased on the
    new folder, so the saved preset finds the same files."""
    path = Path(path)
    problem = output_problem(path) or clobber_problem(path, scene_inputs(scene))
    if problem:
        raise ShadeLabError(f"{path}: cannot write the preset: {problem}")
    text = tomli_w.dumps(_rebased(scene_to_dict(scene), Path(scene.base_dir),
                                  resolve_link(path).absolute().parent))
    with OutputSet() as out:
        out.write("preset", path, lambda handle: handle.write(text.encode("utf-8")))


def _rebased(data: dict, old_dir: Path, new_dir: Path) -> dict:
    """Relative file paths of ``data`` (read from old_dir) made relative to new_dir."""
    if old_dir.resolve() == new_dir.resolve():
        return data

    def rebase(value: str) -> str:
        if not value or Path(value).is_absolute():
            return value
        return Path(os.path.relpath(old_dir.resolve() / value, new_dir.resolve())).as_posix()

    for obj in data["objects"]:
        if obj.get("shape") == "mesh":
            obj["path"] = rebase(obj["path"])
    for material in data["materials"].values():
        if material["texture"] != "checker":
            material["texture"] = rebase(material["texture"])
        if material["bump"] != "bumps":
            material["bump"] = rebase(material["bump"])
    return data


def clone_scene(scene: Scene) -> Scene:
    return copy.deepcopy(scene)
