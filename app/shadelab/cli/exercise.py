"""``shadelab exercise FILE [--answers ANSWERS.toml] [--json OUT]``: grade a student's answers
headless (no display), one line per task and a total; without ``--answers`` it prints the
answer key (the lab's value for every task), as a teacher would see it."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from shadelab.errors import ShadeLabError


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("exercise", help="grade answers to an exercise (presets/exercises/) "
                                        "headless, or print its answer key")
    p.add_argument("exercise", metavar="FILE", help="exercise name or .toml path")
    p.add_argument("--answers", metavar="ANSWERS.toml",
                   help="the student's answers: an [answers] table, task id = answer")
    p.add_argument("--json", metavar="OUT.json", help="write the graded record as JSON")
    p.add_argument("--class", dest="class_dir", metavar="DIR",
                   help="a folder of the class's graded .json records: per task, how many "
                        "passed and the answers given (the teacher's view)")
    p.set_defaults(run=run_exercise)


def _check_output(args: argparse.Namespace, exercise_path: str) -> None:
    from shadelab.imageio import check_writable
    from shadelab.paths import same_file

    if not args.json:
        return
    check_writable(args.json, "--json")
    for flag, path in (("the exercise", exercise_path), ("--answers", args.answers)):
        if path and (same_file(args.json, path)
                     or Path(args.json).absolute() == Path(path).absolute()):
            raise ShadeLabError(f"--json '{args.json}': the same file as {flag}; "
                                "choose another name")


def _write_json(path: str, record: dict) -> None:
    from shadelab.paths import OutputSet

    data = (json.dumps(record, indent=2) + "\n").encode()
    with OutputSet() as out:
        out.write("--json", path, lambda handle: handle.write(data))


def run_exercise(args: argparse.Namespace) -> int:
    from shadelab.exercises import grade_exercise, load_answers, load_exercise
    from shadelab.exercises.headless import api_render

    exercise = load_exercise(args.exercise)
    _check_output(args, exercise.path)
    if args.class_dir is not None:
        from shadelab.exercises.grading import class_summary, load_class_results

        rows = class_summary(exercise, load_class_results(args.class_dir))
        for i, task in enumerate(exercise.tasks, 1):
            print(f"{i:>2}. {task.id}  {rows[task.id].text()}")
        return 0
    if args.answers is None:
        for i, task in enumerate(exercise.tasks, 1):
            task.render = api_render
            expected = task.expected()
            tol = "" if expected.tolerance is None else f" +/- {expected.tolerance:g}"
            print(f"{i:>2}. {task.id}  {task.KIND}: {task.answer_text(expected.value)}{tol}")
        return 0
    answers = load_answers(args.answers, exercise)
    report = grade_exercise(exercise, answers, api_render)
    for line in report.lines():
        print(line)
    if args.json:
        from shadelab import __version__

        _write_json(args.json, report.to_json(__version__))
    return 0
