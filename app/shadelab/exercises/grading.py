"""Grade a whole answer sheet headless: one :class:`Result` per task, a total, and the JSON
record (the exercise file's sha256, the lab's version, each task's value, answer, tolerance
and verdict)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from shadelab.exercises.loader import Exercise
from shadelab.exercises.tasks import Renderer, Result


@dataclass
class Report:
    exercise: Exercise
    results: list[Result]

    @property
    def passed(self) -> int:
        return sum(r.passed for r in self.results)

    def lines(self) -> list[str]:
        """One line per task and the total (what the CLI prints)."""
        width = max(len(t.id) for t in self.exercise.tasks)
        out = []
        for i, (task, r) in enumerate(zip(self.exercise.tasks, self.results, strict=False), 1):
            answer = "-" if r.answer is None else task.answer_text(r.answer)
            out.append(f"{i:>2}. {task.id:<{width}}  {task.KIND:<6}  {r.verdict.upper():<10}"
                       f"  answer {answer}: {r.message}")
        n = len(self.results)
        out.append(f"total: {self.passed}/{n} passed ({100.0 * self.passed / n:.0f} %)")
        return out

    def to_json(self, version: str) -> dict[str, Any]:
        """The record; ``version`` is the lab's (``shadelab.__version__``, passed in by the
        caller: importing the package from here would close an import cycle)."""
        return {"exercise": Path(self.exercise.path).name, "name": self.exercise.name,
                "sha256": self.exercise.sha256, "shadelab_version": version,
                "tasks": [r.to_json() for r in self.results],
                "total": {"passed": self.passed, "count": len(self.results)}}


def grade_exercise(exercise: Exercise, answers: dict[str, Any],
                   render: Renderer | None) -> Report:
    """Grade parsed ``answers`` (task id -> answer; a missing id is unanswered); ``render``
    draws the images (:func:`shadelab.exercises.headless.api_render` headless)."""
    results = []
    for task in exercise.tasks:
        task.render = render
        results.append(task.grade(answers.get(task.id)))
    return Report(exercise, results)


@dataclass
class ClassRow:
    """One task across a class's graded sheets."""

    passed: int
    answered: int
    sheets: int
    answers: list[tuple[str, int]]   # the answers given, most common first (text, count)

    def text(self) -> str:
        common = ", ".join(f"{a} ({n})" for a, n in self.answers[:4]) or "none"
        return (f"class: {self.passed}/{self.sheets} passed, {self.answered} answered; "
                f"answers: {common}")


def _answer_key(answer: Any) -> str:
    """An answer as text, numbers to 3 significant digits (0.5500001 and 0.55 count as one)."""
    if isinstance(answer, bool) or answer is None:
        return str(answer)
    if isinstance(answer, (int, float)):
        return f"{answer:.3g}"
    if isinstance(answer, (list, tuple)):
        return "[" + ", ".join(_answer_key(a) for a in answer) + "]"
    return str(answer)


def class_summary(exercise: Exercise, records: list[dict]) -> dict[str, ClassRow]:
    """Per task: how many of the class's graded records (``shadelab exercise --json``) passed
    and answered it, and the answers given, most common first. A record of another exercise
    file (its sha256 differs) is refused with one line naming it."""
    from collections import Counter

    from shadelab.errors import ShadeLabError

    for i, record in enumerate(records):
        if not isinstance(record, dict) or record.get("sha256") != exercise.sha256:
            name = record.get("_file", f"record {i}") if isinstance(record, dict) else i
            raise ShadeLabError(f"{name}: graded for another exercise file (its sha256 is not "
                                f"{Path(exercise.path).name}'s)")
    rows = {}
    for task in exercise.tasks:
        mine = [t for r in records for t in r.get("tasks", []) if t.get("id") == task.id]
        given = [t for t in mine if t.get("verdict") != "unanswered"]
        counts = Counter(_answer_key(t.get("answer")) for t in given)
        rows[task.id] = ClassRow(sum(t.get("verdict") == "pass" for t in mine), len(given),
                                 len(records), counts.most_common())
    return rows


def load_class_results(folder: str | Path) -> list[dict]:
    """Every ``*.json`` graded record in ``folder`` (one line for a folder that is not one, a
    file that is not JSON)."""
    import json

    from shadelab.errors import ShadeLabError

    folder = Path(folder)
    if not folder.is_dir():
        raise ShadeLabError(f"--class '{folder}': not a folder of graded .json records")
    records = []
    for path in sorted(folder.glob("*.json")):
        try:
            record = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
            raise ShadeLabError(f"{path.name}: not a graded record ({exc})") from None
        if isinstance(record, dict):
            record["_file"] = path.name
        records.append(record)
    if not records:
        raise ShadeLabError(f"--class '{folder}': no .json graded records in it")
    return records
