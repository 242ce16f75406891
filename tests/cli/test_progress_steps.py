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


def test_one_long_step_ticks_its_elapsed_time_then_clears_the_line(capsys, monkeypatch):
    monkeypatch.setattr(progress, "SHOW_STEPS", True)
    monkeypatch.setattr(progress, "STEP_DELAY_S", 0.1)
    monkeypatch.setattr(progress, "TICK_S", 0.05)
    with progress.busy("reading quick.obj"):
        pass
    assert capsys.readouterr().err == ""                  # under the delay: nothing
    with progress.busy("reading huge.obj"):
        time.sleep(0.5)
    err = capsys.readouterr().err
    lines = [part for part in err.split("\r") if part.strip()]
    assert len(lines) >= 3 and all(part.startswith("reading huge.obj ... ") for part in lines)
    seconds = [float(part.split("... ")[1].split(" s")[0]) for part in lines]
    assert seconds == sorted(seconds) and 0.1 <= seconds[0] < seconds[-1] <= 0.6
    assert err.endswith("\r") and err.rsplit("\r", 2)[-2].strip() == ""   # line cleared


def test_busy_is_silent_outside_the_cli_and_passes_errors_through(capsys, monkeypatch):
    import pytest

    monkeypatch.setattr(progress, "SHOW_STEPS", False)
    with progress.busy("x"):
        time.sleep(0.01)
    monkeypatch.setattr(progress, "SHOW_STEPS", True)
    with pytest.raises(ValueError, match="boom"):
        with progress.busy("y"):
            raise ValueError("boom")
    assert capsys.readouterr().err == ""


def test_mesh_file_reading_goes_through_busy(monkeypatch, tmp_path):
    from shadelab.geometry import mesh as mesh_module
    from shadelab.scene import load_preset

    seen = []

    class Spy:
        def __init__(self, desc):
            seen.append(desc)

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

    monkeypatch.setattr(mesh_module, "busy", Spy)
    (tmp_path / "tri.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    scene = load_preset("shadows", ["objects.2.shape=mesh", f"objects.2.path={tmp_path}/tri.obj"])
    mesh_module.scene_meshes(scene)
    assert any("reading 'tri.obj'" in d for d in seen)
    assert any("triangles' normals" in d for d in seen)


def test_the_cli_shows_steps_only_on_a_terminal(monkeypatch):
    import io

    from shadelab.cli import _interactive, main

    class Tty(io.StringIO):
        def isatty(self):
            return True

    assert _interactive(Tty()) and not _interactive(io.StringIO())
    closed = io.StringIO()
    closed.close()
    assert not _interactive(closed)
    monkeypatch.setattr(progress, "SHOW_STEPS", True)
    assert main(["presets"]) == 0                   # stderr captured by pytest: not a tty
    assert progress.SHOW_STEPS is False
