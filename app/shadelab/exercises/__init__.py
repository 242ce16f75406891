"""Exercises: predict, then reveal (ARCHITECTURE.md, "Exercises").

Files like lessons (``presets/exercises/*.toml``) whose tasks ask the student for a number, a
picture, a parameter setting or a pixel, grade the answer against the lab's own value
(``shadelab.probe`` / ``render``, the radiosity form factors, the ray tree) and reveal the
terms that show why. Pure: no GL or GUI import; images come through ``shadelab.api`` (headless)
or from the viewer's GL side.
"""

from shadelab.exercises.files import list_exercises, resolve_exercise
from shadelab.exercises.grading import Report, grade_exercise
from shadelab.exercises.loader import Exercise, load_answers, load_exercise
from shadelab.exercises.tasks import KINDS, Expected, NeedImages, Result, Reveal, Shot, Task

__all__ = ["KINDS", "Exercise", "Expected", "NeedImages", "Report", "Result", "Reveal", "Shot",
           "Task", "grade_exercise", "list_exercises", "load_answers", "load_exercise",
           "resolve_exercise"]
