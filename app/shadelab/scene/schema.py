"""``presets/schema.json`` for editors, generated from the field specs of shadelab.scene.model.

One table drives validation and the schema, so they cannot drift; a test compares the
committed file with :func:`preset_schema`.
"""

from __future__ import annotations

import dataclasses
import json
import math

from shadelab.scene.model import (
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


def _number(lo: float, hi: float) -> dict:
    out: dict = {"type": "number"}
    if math.isfinite(lo):
        out["minimum"] = lo
    if math.isfinite(hi):
        out["maximum"] = hi
    return out


def _field_schema(spec: tuple) -> dict:
    kind, *args = spec
    vec = {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3}
    if kind == "float":
        return _number(*args)
    if kind == "int":
        return {"type": "integer", "minimum": args[0], "maximum": args[1]}
    if kind == "bool":
        return {"type": "boolean"}
    if kind == "str":
        return {"type": "string", "enum": list(args[0])} if args[0] else {"type": "string"}
    if kind == "rgb":
        return {**vec, "items": _number(0.0, args[0])}
    if kind == "rgb01":
        return {**vec, "items": {"type": "number", "minimum": 0, "maximum": 1}}
    if kind == "vec3":
        return {**vec, "items": _number(*args)}
    if kind == "vec3s":
        return {"type": "array", "items": {**vec, "items": _number(*args)}}
    raise AssertionError(kind)


def table_schema(cls: type) -> dict:
    props = {}
    for f in dataclasses.fields(cls):
        if "spec" in f.metadata:
            props[f.name] = {**_field_schema(f.metadata["spec"]),
                             "description": f.metadata.get("doc", "")}
    return {"type": "object", "properties": props, "additionalProperties": False}


def preset_schema() -> dict:
    scene_fields = {f.name: f for f in dataclasses.fields(Scene)}
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": "ShadeLab preset",
        "type": "object",
        "required": ["schema_version"],
        "additionalProperties": False,
        "properties": {
            "schema_version": {"const": SCHEMA_VERSION},
            "description": {"type": "string"},
            "Ia": _field_schema(scene_fields["Ia"].metadata["spec"]),
            "camera": table_schema(Camera),
            "render": table_schema(RenderSettings),
            "raytrace": table_schema(RaytraceSettings),
            "radiosity": table_schema(RadiositySettings),
            "lights": {"type": "array", "items": table_schema(Light)},
            "materials": {"type": "object", "additionalProperties": table_schema(Material)},
            "objects": {"type": "array", "items": table_schema(Object)},
        },
    }


def schema_text() -> str:
    return json.dumps(preset_schema(), indent=2, sort_keys=False) + "\n"


if __name__ == "__main__":  # python -m shadelab.scene.schema > presets/schema.json
    print(schema_text(), end="")
