"""Exercise and answer files: read, validate, build tasks (no GL, no GUI).

An exercise is a TOML file like a lesson: ``name``, ``description`` and ``[[tasks]]``, each
task one of four kinds (``number``, ``choice``, ``match``, ``pixel``; see
:mod:`shadelab.exercises.tasks`). Every task names a preset, ``--set`` overrides and an image
size; the value it is graded against is computed by the lab when asked, never stored.
A broken file is one line naming the file, the task and the key (:class:`ShadeLabError`).

An answer file holds one ``[answers]`` table: task id -> the student's answer (a number, a
letter, a list of parameter values, or an [x, y] pixel).
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from shadelab.errors import ShadeLabError
from shadelab.scene.preset import load_preset

FILE_KEYS = {"name", "description", "tasks"}
COMMON_KEYS = {"id", "kind", "title", "question", "hint", "reveal", "preset", "set", "size",
               "shading", "specular"}
SHADINGS = ("flat", "gouraud", "phong")
SPECULARS = ("phong", "blinn")
DEFAULT_SIZE = (64, 48)
MAX_SIZE = 1024
MAX_TASKS = 200


def exercises_dir() -> Path:
    from shadelab.resources import presets_dir

    return Path(presets_dir()) / "exercises"


def list_exercises() -> list[str]:
    return sorted(p.stem for p in exercises_dir().glob("*.toml"))


def resolve_exercise(name_or_path: str | Path) -> Path:
    text = str(name_or_path)
    path = Path(text)
    if path.suffix == ".toml" or "/" in text:
        if not path.is_file():
            raise ShadeLabError(f"exercise '{text}': file not found")
        return path
    path = exercises_dir() / f"{text}.toml"
    if not path.is_file():
        raise ShadeLabError(f"exercise '{text}': expected one of "
                            f"{', '.join(list_exercises()) or '(none shipped)'}, or a .toml path")
    return path


def sha256_of(path: str | Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


# ---------------------------------------------------------------- typed reads


class Where:
    """Names the place of a value in a file for the one-line error."""

    def __init__(self, source: str, task: str):
        self.source, self.task = source, task

    def fail(self, key: str, what: str) -> ShadeLabError:
        return ShadeLabError(f"{self.source}: {self.task}: {key}: {what}")

    def bad(self, what: str) -> ShadeLabError:
        return ShadeLabError(f"{self.source}: {self.task}: {what}")


def is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) \
        and math.isfinite(value)


def get_str(raw: dict, key: str, where: Where, default: str | None = None,
            choices: tuple[str, ...] | None = None) -> str:
    if key not in raw:
        if default is None:
            raise where.fail(key, "missing (expected a string)")
        return default
    value = raw[key]
    if not isinstance(value, str) or (default is None and not value.strip()):
        raise where.fail(key, f"expected a non-empty string, got {_show(value)}")
    if choices is not None and value not in choices:
        raise where.fail(key, f"'{value}': expected one of {', '.join(choices)}")
    return value


def get_number(raw: dict, key: str, where: Where, default: float | None = None,
               lo: float = -math.inf, hi: float = math.inf) -> float:
    if key not in raw:
        if default is None:
            raise where.fail(key, "missing (expected a number)")
        return default
    value = raw[key]
    if not is_number(value):
        raise where.fail(key, f"expected a finite number, got {_show(value)}")
    if not lo <= value <= hi:
        raise where.fail(key, f"{value}: expected a number in [{lo}, {hi}]")
    return float(value)


def get_int(raw: dict, key: str, where: Where, default: int | None = None,
            lo: int = 0, hi: int = 10**6) -> int:
    if key not in raw:
        if default is None:
            raise where.fail(key, "missing (expected an integer)")
        return default
    value = raw[key]
    if not isinstance(value, int) or isinstance(value, bool):
        raise where.fail(key, f"expected an integer, got {_show(value)}")
    if not lo <= value <= hi:
        raise where.fail(key, f"{value}: expected an integer in [{lo}, {hi}]")
    return value


def get_strings(raw: dict, key: str, where: Where, required: bool = False) -> list[str]:
    if key not in raw:
        if required:
            raise where.fail(key, "missing (expected a list of strings)")
        return []
    value = raw[key]
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise where.fail(key, f"expected a list of strings, got {_show(value)}")
    return list(value)


def get_numbers(raw: dict, key: str, where: Where, length: int | None = None,
                required: bool = True) -> list[float] | None:
    if key not in raw:
        if required:
            raise where.fail(key, "missing (expected a list of numbers)")
        return None
    value = raw[key]
    if not isinstance(value, list) or not all(is_number(v) for v in value):
        raise where.fail(key, f"expected a list of finite numbers, got {_show(value)}")
    if length is not None and len(value) != length:
        raise where.fail(key, f"expected {length} numbers, got {len(value)}")
    return [float(v) for v in value]


def get_pixel(raw: dict, key: str, where: Where, size: tuple[int, int]) -> tuple[int, int]:
    value = raw.get(key)
    if value is None:
        raise where.fail(key, "missing (expected [x, y])")
    return check_pixel(value, where, key, size)


def check_pixel(value: Any, where: Where, key: str, size: tuple[int, int]) -> tuple[int, int]:
    if not isinstance(value, list) or len(value) != 2 or not all(
            isinstance(v, int) and not isinstance(v, bool) for v in value):
        raise where.fail(key, f"expected an [x, y] pixel of integers, got {_show(value)}")
    x, y = value
    if not (0 <= x < size[0] and 0 <= y < size[1]):
        raise where.fail(key, f"[{x}, {y}]: outside the {size[0]}x{size[1]} image")
    return int(x), int(y)


def _show(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def check_keys(raw: dict, allowed: set[str], where: Where) -> None:
    unknown = sorted(str(k) for k in set(raw) - allowed)
    if unknown:
        raise where.fail(unknown[0], f"unknown key (expected {', '.join(sorted(allowed))})")


@dataclass
class Common:
    """What every task has (parsed by :class:`shadelab.exercises.tasks.Task`)."""

    preset: str
    set: list[str] = field(default_factory=list)
    size: tuple[int, int] = DEFAULT_SIZE
    shading: str | None = None
    specular: str | None = None


def parse_common(item: dict, where: Where, base: Path) -> Common:
    preset = get_str(item, "preset", where)
    if preset.endswith(".toml") and not Path(preset).is_absolute():
        preset = str(base / preset)  # a preset file next to the exercise
    overrides = get_strings(item, "set", where)
    size = DEFAULT_SIZE
    if "size" in item:
        value = item["size"]
        if not isinstance(value, list) or len(value) != 2 or not all(
                isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= MAX_SIZE
                for v in value):
            raise where.fail("size", f"expected [width, height] in 1..{MAX_SIZE}, "
                                     f"got {_show(value)}")
        size = (int(value[0]), int(value[1]))
    shading = get_str(item, "shading", where, default="", choices=("", *SHADINGS)) or None
    specular = get_str(item, "specular", where, default="", choices=("", *SPECULARS)) or None
    return Common(preset, overrides, size, shading, specular)


def load_scene(common: Common, extra: list[str] | None = None):
    return load_preset(common.preset, [*common.set, *(extra or [])])
