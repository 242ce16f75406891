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
