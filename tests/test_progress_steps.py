"""Long valid work in the CLI shows a tqdm bar on stderr (issue 12): steps() wraps the loops
over objects (validation, meshes and normals); quiet outside the CLI and for short work."""

from __future__ import annotations

import time

from shadelab import progress


def test_steps_is_silent_unless_the_cli_asks(capsys, monkeypatch):
    monkeypatch.setattr(progress, "SHOW_STEPS", False)
    items = [1, 2, 3]
    assert progress.steps(items, 3, "x") is items
    assert capsys.readouterr().err == ""


def test_a_step_over_the_delay_shows_a_bar_a_short_one_none(capsys, monkeypatch):
    monkeypatch.setattr(progress, "SHOW_STEPS", True)
    monkeypatch.setattr(progress, "STEP_DELAY_S", 0.2)
    assert list(progress.steps(range(5), 5, "quick")) == [0, 1, 2, 3, 4]
    assert "quick" not in capsys.readouterr().err        # under the delay: no bar
    for _ in progress.steps(range(8), 8, "validating objects"):
        time.sleep(0.08)                                  # 0.64 s > 0.2 s
    err = capsys.readouterr().err
    assert "validating objects" in err and "/8" in err


def test_validation_and_meshes_go_through_steps(monkeypatch):
    from shadelab.geometry.mesh import scene_meshes
    from shadelab.scene import load_preset

    seen = []

    def spy(items, total=None, desc=""):
        seen.append((desc, total))
        return items

    monkeypatch.setattr("shadelab.scene.preset.steps", spy)
    monkeypatch.setattr("shadelab.geometry.mesh.steps", spy)
    scene = load_preset("cornell")
    scene_meshes(scene)
    n = len(scene.objects)
    assert ("validating objects", n) in seen and ("meshes and normals", n) in seen
