"""Exercise and answer files: broken ones are one line naming the task and the key (exit 2
from the CLI); a full answer sheet is graded headless through the CLI, with its JSON record;
the shipped set's values are the lab's own, recomputed."""

from __future__ import annotations

import hashlib
import json

import pytest

import shadelab
from shadelab.cli import main
from shadelab.errors import ShadeLabError
from shadelab.exercises import KINDS, list_exercises, load_answers, load_exercise

GOOD = """
[[tasks]]
id = "fatt"
kind = "number"
question = "f_att at d = 5?"
preset = "lecture"
quantity = "f_att(d)"
distance = 5.0
tolerance = 0.01

[[tasks]]
id = "nl"
kind = "number"
question = "N.L?"
preset = "lecture"
quantity = "N.L"
pixel = [30, 25]
tolerance = 0.05

[[tasks]]
id = "pick"
kind = "choice"
question = "Which is Blinn?"
preset = "ks-n-grid"
correct = "blinn"
[[tasks.options]]
label = "phong"
specular = "phong"
[[tasks.options]]
label = "blinn"
specular = "blinn"

[[tasks]]
id = "kd"
kind = "match"
question = "Match kd"
preset = "lecture"
params = ["materials.plastic.kd"]
target = [0.6]
threshold = 0.002

[[tasks]]
id = "spot"
kind = "pixel"
question = "The highlight?"
preset = "lecture"
set = ["render.shadows=none"]
region = "specular"
tolerance = 1
"""


@pytest.mark.parametrize("body, message", [
    ('[[tasks]]\nid = "a"\nkind = "number"\nquestion = "?"\npreset = "lecture"\n'
     'quantity = "f_att(d)"\ndistance = 1.0\ntolerance = 0.1\ncolour = 1\n',
     r"ex.toml: tasks\[0\] \('a'\): colour: unknown key"),
    ('[[tasks]]\nid = "a"\nkind = "number"\nquestion = "?"\npreset = "lecture"\n'
     'quantity = "f_att(d)"\ndistance = "far"\ntolerance = 0.1\n',
     r"ex.toml: tasks\[0\] \('a'\): distance: expected a finite number, got 'far'"),
    ('[[tasks]]\nid = "a"\nkind = "number"\nquestion = "?"\npreset = "lecture"\n'
     'quantity = "N.L"\npixel = [999, 2]\ntolerance = 0.1\n',
     r"ex.toml: tasks\[0\] \('a'\): pixel: \[999, 2\]: outside the 64x48 image"),
    ('[[tasks]]\nid = "a"\nkind = "guess"\nquestion = "?"\npreset = "lecture"\n',
     r"ex.toml: tasks\[0\] \('a'\): kind: 'guess': expected one of number, choice"),
    ('[[tasks]]\nid = "a"\nkind = "match"\nquestion = "?"\npreset = "lecture"\n'
     'params = ["materials.plastic.kd"]\ntarget = [0.5, 1]\nthreshold = 0.1\n',
     r"ex.toml: tasks\[0\] \('a'\): target: expected 1 numbers, got 2"),
    ('[[tasks]]\nid = "a"\nkind = "number"\nquestion = "?"\npreset = "lecture"\n'
     'set = ["materials.plastic.kd=7"]\nquantity = "f_att(d)"\ndistance = 1.0\n'
     'tolerance = 0.1\n', r"ex.toml: tasks\[0\] \('a'\): .*kd"),
    ('[[tasks]]\nkind = "number"\n', r"ex.toml: tasks\[0\]: id: missing"),
])
def test_a_broken_exercise_is_one_line_naming_the_task_and_key(write_exercise, capsys, body,
                                                               message):
    path = write_exercise(body)
    with pytest.raises(ShadeLabError, match=message):
        load_exercise(path)
    assert main(["exercise", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("shadelab: error: ") and "Traceback" not in err


@pytest.mark.parametrize("answers, message", [
    ('[answers]\nnope = 1\n', r"a.toml: answers.nope: no such task in ex.toml"),
    ('[answers]\nfatt = "big"\n', r"a.toml: answers.fatt: expected a finite number, got 'big'"),
    ('[answers]\npick = "E"\n', r"a.toml: answers.pick: expected one of A, B, got 'E'"),
    ('[answers]\nkd = 0.5\n', r"a.toml: answers.kd: expected a list of 1 numbers"),
    ('[answers]\nspot = [1, 99]\n', r"a.toml: answers.spot: pixel: \[1, 99\]: outside"),
    ('fatt = 1\n', r"a.toml: file: fatt: unknown key"),
    ('[answers\n', r"a.toml"),
])
def test_a_broken_answer_file_is_one_line_naming_the_task(write_exercise, tmp_path, capsys,
                                                         answers, message):
    exercise = write_exercise(GOOD)
    path = tmp_path / "a.toml"
    path.write_text(answers, encoding="utf-8")
    with pytest.raises(ShadeLabError, match=message):
        load_answers(path, load_exercise(exercise, check=False))
    assert main(["exercise", str(exercise), "--answers", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err


def test_a_full_answer_sheet_is_graded_headless_with_its_json(write_exercise, tmp_path,
                                                             capsys, monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    exercise_path = write_exercise(GOOD)
    key = load_exercise(exercise_path)
    from shadelab.exercises.headless import api_render

    values = {}
    for task in key.tasks:
        task.render = api_render
        values[task.id] = task.expected().value
    fatt = values["fatt"]
    answers = tmp_path / "a.toml"
    answers.write_text(f'[answers]\nfatt = {fatt + 0.02}\nnl = {values["nl"]}\n'
                       f'pick = "{values["pick"]}"\nkd = [0.6]\n'
                       f'spot = [{values["spot"][0]}, {values["spot"][1]}]\n', encoding="utf-8")
    out = tmp_path / "out.json"
    assert main(["exercise", str(exercise_path), "--answers", str(answers),
                 "--json", str(out)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 6 and lines[-1].startswith("total: 4/5 passed")
    assert "FAIL" in lines[0] and all("PASS" in line for line in lines[1:5])
    record = json.loads(out.read_text())  # version passed by the CLI
    assert record["sha256"] == hashlib.sha256(exercise_path.read_bytes()).hexdigest()
    assert record["shadelab_version"] == shadelab.__version__
    assert record["total"] == {"passed": 4, "count": 5}
    first = record["tasks"][0]
    assert first["value"] == pytest.approx(fatt) and first["answer"] == pytest.approx(fatt + 0.02)
    assert first["tolerance"] == 0.01 and first["verdict"] == "fail"
    assert [t["verdict"] for t in record["tasks"][1:]] == ["pass"] * 4


def test_json_never_overwrites_an_input(write_exercise, tmp_path, capsys):
    exercise_path = write_exercise(GOOD)
    answers = tmp_path / "a.toml"
    answers.write_text("[answers]\nfatt = 1.0\n", encoding="utf-8")
    before = (exercise_path.read_bytes(), answers.read_bytes())
    for target in (exercise_path, answers):
        assert main(["exercise", str(exercise_path), "--answers", str(answers),
                     "--json", str(target)]) == 2
        assert "the same file as" in capsys.readouterr().err
    assert (exercise_path.read_bytes(), answers.read_bytes()) == before


def test_the_shipped_set_covers_the_lecture_and_its_values_are_the_labs(capsys):
    assert "phong-to-radiosity" in list_exercises()
    exercise = load_exercise("phong-to-radiosity")
    assert len(exercise.tasks) >= 16
    assert {t.KIND for t in exercise.tasks} == set(KINDS)
    assert all(t.reveal_text and t.question for t in exercise.tasks)
    # the answer key, recomputed by the lab (nothing is stored in the file)
    assert main(["exercise", "phong-to-radiosity"]) == 0
    key = capsys.readouterr().out.splitlines()
    assert len(key) == len(exercise.tasks)
    by_id = {t.id: t for t in exercise.tasks}
    task = by_id["n-dot-l"]
    p = shadelab.probe(shadelab.load_preset("lecture"), task.pixel, task.size)
    import numpy as np

    want = max(float(np.dot(p["normal"], p["lights"][0]["to_light"])), 0.0)
    assert any(line.split()[1] == "n-dot-l" and f"{want:.4g}" in line for line in key)
    light = shadelab.load_preset("lecture", {"lights.0.c1": 0.25}).lights[0]
    assert 1.0 / (light.c1 + 2 * light.c2 + 4 * light.c3) > 1.0   # the clamp is active
    assert any(line.split()[1] == "f-att-clamp" and ": 1 +/-" in line for line in key)


def test_view_exercise_brings_the_exercise_window_forward():
    """`shadelab view --exercise` opens the sheet and asks for its window in front (it was
    docked behind the Equation tab, out of sight at 1024x768)."""
    from shadelab.exercises.loader import load_exercise
    from shadelab.lab.panel_names import unknown_panel
    from shadelab.lab.state import AppState
    from shadelab.scene.preset import load_preset
    from shadelab.ui.exercise_panel import open_exercise, panel_of

    state = AppState.from_scene(load_preset("lecture"), "lecture")
    open_exercise(state, load_exercise("phong-to-radiosity"))
    assert state.walk.focus_request == "Exercise" and unknown_panel("Exercise") is None
    assert panel_of(state).index == 0
