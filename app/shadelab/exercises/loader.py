"""Load an exercise file into its tasks, and a student's answer file (see
:mod:`shadelab.exercises.files` for the format)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from shadelab.errors import ShadeLabError
from shadelab.exercises.files import (
    COMMON_KEYS,
    FILE_KEYS,
    MAX_TASKS,
    Where,
    check_keys,
    get_str,
    resolve_exercise,
    sha256_of,
)
from shadelab.exercises.tasks import KINDS, Task
from shadelab.scene.preset import read_toml

# ---------------------------------------------------------------- the exercise


@dataclass
class Exercise:
    name: str
    description: str
    tasks: list[Task]
    path: str = ""
    sha256: str = ""

    def task(self, task_id: str):
        for task in self.tasks:
            if task.id == task_id:
                return task
        raise KeyError(task_id)


def load_exercise(name_or_path: str | Path, check: bool = True) -> Exercise:
    """Read and validate an exercise file; ``check`` also loads every task's scenes (their
    presets and overrides), so a broken override is reported before any student answers."""
    path = resolve_exercise(name_or_path)
    raw = read_toml(path)
    source = path.name
    top = Where(source, "file")
    check_keys(raw, FILE_KEYS, top)
    name = get_str(raw, "name", top, default=path.stem)
    description = get_str(raw, "description", top, default="")
    items = raw.get("tasks")
    if not isinstance(items, list) or not items:
        raise ShadeLabError(f"{source}: expected at least one [[tasks]] table")
    if len(items) > MAX_TASKS:
        raise ShadeLabError(f"{source}: {len(items)} tasks, expected at most {MAX_TASKS}")
    tasks, seen = [], set()
    for i, item in enumerate(items):
        label = f"tasks[{i}]"
        if not isinstance(item, dict):
            raise ShadeLabError(f"{source}: {label}: expected a table")
        if isinstance(item.get("id"), str) and item["id"]:
            label = f"tasks[{i}] ('{item['id']}')"
        where = Where(source, label)
        task_id = get_str(item, "id", where)
        if task_id in seen:
            raise where.fail("id", f"'{task_id}' is used by an earlier task")
        seen.add(task_id)
        kind = get_str(item, "kind", where, choices=tuple(KINDS))
        cls = KINDS[kind]
        check_keys(item, COMMON_KEYS | cls.KEYS, where)
        task = cls(where, item, base=path.parent)
        tasks.append(task)
    exercise = Exercise(name, description, tasks, str(path), sha256_of(path))
    if check:
        for task in tasks:
            task.check()
    return exercise


# ---------------------------------------------------------------- answers


def load_answers(path: str | Path, exercise: Exercise) -> dict[str, Any]:
    """task id -> the student's answer, each checked against its task's kind."""
    p = Path(path)
    if not p.is_file():
        raise ShadeLabError(f"answers '{path}': file not found")
    raw = read_toml(p)
    source = p.name
    check_keys(raw, {"answers", "student"}, Where(source, "file"))
    answers = raw.get("answers")
    if not isinstance(answers, dict):
        raise ShadeLabError(f"{source}: expected an [answers] table (task id = answer)")
    ids = [t.id for t in exercise.tasks]
    out = {}
    for key, value in answers.items():
        if key not in ids:
            raise ShadeLabError(f"{source}: answers.{key}: no such task in "
                                f"{Path(exercise.path).name} (expected one of {', '.join(ids)})")
        task = exercise.task(key)
        out[key] = task.parse_answer(value, Where(source, f"answers.{key}"))
    return out
