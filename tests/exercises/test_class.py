"""The teacher's view of a class: graded records (``shadelab exercise --json``) summed per
task — how many passed and answered, the answers given, most common first (issue 23)."""

from __future__ import annotations

import json

import pytest

from shadelab.cli import main
from shadelab.errors import ShadeLabError
from shadelab.exercises.grading import class_summary
from shadelab.exercises.loader import load_exercise


def _record(exercise, verdicts: dict, answers: dict) -> dict:
    return {"sha256": exercise.sha256, "tasks": [
        {"id": t.id, "verdict": verdicts.get(t.id, "unanswered"), "answer": answers.get(t.id)}
        for t in exercise.tasks]}


def test_the_class_summary_counts_passes_answers_and_their_spread():
    ex = load_exercise("phong-to-radiosity")
    first, second = ex.tasks[0].id, ex.tasks[1].id
    records = [_record(ex, {first: "pass", second: "fail"}, {first: "B", second: 0.5500001}),
               _record(ex, {first: "fail", second: "fail"}, {first: "A", second: 0.55}),
               _record(ex, {first: "pass"}, {first: "B"})]
    rows = class_summary(ex, records)
    assert (rows[first].passed, rows[first].answered, rows[first].sheets) == (2, 3, 3)
    assert rows[first].answers == [("B", 2), ("A", 1)]
    assert (rows[second].passed, rows[second].answered) == (0, 2)
    assert rows[second].answers == [("0.55", 2)]     # 3 significant digits: one answer
    assert rows[ex.tasks[2].id].answered == 0
    assert rows[first].text() == "class: 2/3 passed, 3 answered; answers: B (2), A (1)"


def test_records_of_another_exercise_file_are_refused():
    ex = load_exercise("phong-to-radiosity")
    with pytest.raises(ShadeLabError, match="other.json: graded for another exercise file"):
        class_summary(ex, [{"sha256": "0" * 64, "tasks": [], "_file": "other.json"}])


def test_shadelab_exercise_class_prints_one_line_per_task(tmp_path, capsys):
    ex = load_exercise("phong-to-radiosity")
    first = ex.tasks[0].id
    for i, verdict in enumerate(("pass", "fail")):
        record = _record(ex, {first: verdict}, {first: "AB"[i]})
        (tmp_path / f"student{i}.json").write_text(json.dumps(record))
    assert main(["exercise", "phong-to-radiosity", "--class", str(tmp_path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == len(ex.tasks)
    assert lines[0].endswith(f"{first}  class: 1/2 passed, 2 answered; answers: A (1), B (1)")
    (tmp_path / "notes.json").write_text("{not json")
    assert main(["exercise", "phong-to-radiosity", "--class", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "notes.json: not a graded record" in err
    assert main(["exercise", "phong-to-radiosity", "--class", str(tmp_path / "no")]) == 2


def test_the_teacher_panel_loads_the_class(tmp_path):
    from shadelab.lab.state import AppState
    from shadelab.scene.preset import load_preset
    from shadelab.ui.exercise_panel import load_class, open_exercise, panel_of

    state = AppState.from_scene(load_preset("lecture"), "lecture")
    ex = load_exercise("phong-to-radiosity")
    open_exercise(state, ex)
    panel = panel_of(state)
    load_class(panel, str(tmp_path / "missing"))
    assert panel.error.startswith("--class") and not panel.class_rows
    (tmp_path / "s.json").write_text(json.dumps(_record(ex, {ex.tasks[0].id: "pass"},
                                                        {ex.tasks[0].id: "B"})))
    load_class(panel, str(tmp_path))
    assert not panel.error and panel.class_rows[ex.tasks[0].id].passed == 1
