"""The autosaved session (issue 12, class 6 and item 9): one file, written atomically; a damaged
one never stops the viewer, is kept aside under a new name and is named in the status line."""

from __future__ import annotations

import argparse
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from shadelab.lab import session as session_mod
from shadelab.lab.session import autosave_path, load_session, move_aside, save_session
from shadelab.scene.model import Object
from shadelab.scene.preset import load_preset, scene_to_dict

TETRA = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"


@pytest.fixture(autouse=True)
def _fresh_session_memory(monkeypatch):
    """Each test starts as a new process would: no session file read or written yet."""
    monkeypatch.setattr(session_mod, "_verified", set())


def damaged_copies() -> list[Path]:
    return sorted(autosave_path().parent.glob("autosave.damaged-*.toml"))


def a_valid_session() -> bytes:
    scene = load_preset("cornell")
    scene.materials["red"].kd = 0.125
    save_session(scene, "cornell")
    return autosave_path().read_bytes()


DAMAGE = {
    "truncated": lambda good: good[: len(good) // 2],
    "json-list": lambda good: b"[]",
    "json-null": lambda good: b"null",
    "empty": lambda good: b"",
    "deep-nesting-recursion": lambda good: b"x = " + b"[" * 5000 + b"]" * 5000 + b"\n",
    "deep-nesting-over-limit": lambda good: good + b"\n[session.a.b.c.d.e.f.g.h.i]\nz = 1\n",
    "not-utf8": lambda good: good.replace(b"Cornell", "Cörnell".encode("latin-1")),
    "utf16": lambda good: good.decode().encode("utf-16"),
    "binary": lambda good: bytes(range(256)) * 4,
    "no-scene-table": lambda good: b"[session]\nformat = 1\nsource = 'cornell'\n",
    "scene-not-a-table": lambda good: b"scene = 3\n[session]\nformat = 1\n",
    "unknown-format": lambda good: good.replace(b"format = 1", b"format = 99"),
    "field-out-of-range": lambda good: good.replace(b"Ia = [\n    0.0,", b"Ia = [\n    -5.0,"),
}


@pytest.mark.parametrize("kind", sorted(DAMAGE))
def test_a_damaged_session_is_moved_aside_and_reported(kind):
    bad = DAMAGE[kind](a_valid_session())
    autosave_path().write_bytes(bad)
    result = load_session()
    assert not result and result.scene is None          # start from the preset
    assert "damaged" in result.note and "\n" not in result.note
    copies = damaged_copies()
    assert copies == [result.damaged_copy] and copies[0].name in result.note
    assert copies[0].read_bytes() == bad                  # kept byte for byte
    assert not autosave_path().exists()
    assert not load_session() and load_session().note == ""   # nothing left to complain about


def test_a_valid_session_round_trips_with_relative_mesh_paths(tmp_path):
    folder = tmp_path / "project"
    folder.mkdir()
    (folder / "tetra.obj").write_text(TETRA)
    scene = load_preset("cornell")
    scene.base_dir = str(folder)
    scene.objects.append(Object(shape="mesh", path="tetra.obj", material="white"))
    save_session(scene, "cornell")
    result = load_session()
    assert result and result.note == "" and result.source == "cornell"
    assert result.scene.base_dir == str(folder)
    assert scene_to_dict(result.scene) == scene_to_dict(scene)
    assert not damaged_copies()
    text = autosave_path().read_text()
    assert "[session]" in text and "[scene]" in text     # one file: scene and metadata
    assert not autosave_path().with_suffix(".json").exists()


def test_a_session_naming_a_mesh_that_is_gone_restores_the_rest(tmp_path):
    folder = tmp_path / "project"
    folder.mkdir()
    (folder / "tetra.obj").write_text(TETRA)
    scene = load_preset("cornell")
    count = len(scene.objects)
    scene.base_dir = str(folder)
    scene.objects.append(Object(shape="mesh", path="tetra.obj", material="white"))
    scene.materials["red"].kd = 0.125
    save_session(scene, "cornell")
    saved = autosave_path().read_bytes()
    (folder / "tetra.obj").unlink()
    result = load_session()
    assert result and result.source == "cornell"
    assert len(result.scene.objects) == count             # every other object kept
    assert all(o.path != "tetra.obj" for o in result.scene.objects)
    assert result.scene.materials["red"].kd == 0.125      # the edits kept
    assert "tetra.obj" in result.note and "restored without" in result.note
    assert result.damaged_copy.read_bytes() == saved       # the original still names the mesh


def test_a_missing_texture_is_dropped_the_material_kept(tmp_path):
    scene = load_preset("cornell")
    image = tmp_path / "wood.png"
    image.write_bytes(b"not read here")
    scene.materials["red"].texture = str(image)
    save_session(scene, "cornell")
    image.unlink()
    result = load_session()
    assert result and result.scene.materials["red"].texture == ""
    assert "wood.png" in result.note and len(damaged_copies()) == 1


def test_the_older_two_file_session_still_restores():
    from shadelab.scene.preset import save_preset

    scene = load_preset("cornell")
    scene.materials["red"].kd = 0.25
    autosave_path().parent.mkdir(parents=True, exist_ok=True)
    save_preset(scene, autosave_path())
    autosave_path().with_suffix(".json").write_text(
        '{"source": "cornell", "name": "cornell", "base_dir": "%s"}' % scene.base_dir)
    result = load_session()
    assert result and result.source == "cornell" and result.note == ""
    assert result.scene.materials["red"].kd == 0.25
    save_session(result.scene, result.source)             # rewritten as one file
    assert not autosave_path().with_suffix(".json").exists()
    assert load_session().scene.materials["red"].kd == 0.25


def test_a_damaged_session_not_read_this_run_is_kept_not_overwritten():
    """``view --fresh`` never reads the session; its first autosave must not replace a damaged
    file the user has not been told about."""
    autosave_path().parent.mkdir(parents=True, exist_ok=True)
    autosave_path().write_bytes(b"[[[ damaged")
    save_session(load_preset("cornell"), "cornell")
    copies = damaged_copies()
    assert len(copies) == 1 and copies[0].read_bytes() == b"[[[ damaged"
    assert load_session().source == "cornell"


def test_moving_aside_never_replaces_an_earlier_copy():
    autosave_path().parent.mkdir(parents=True, exist_ok=True)
    made = []
    for i in range(3):  # three damages within one second: three names
        autosave_path().write_bytes(f"damage {i}".encode())
        made.append(move_aside(autosave_path()))
    assert len(set(made)) == 3
    assert sorted(p.read_text() for p in made) == ["damage 0", "damage 1", "damage 2"]


def test_a_killed_writers_stale_temporary_is_swept_a_live_one_kept():
    a_valid_session()
    folder = autosave_path().parent
    stale, live = folder / ".autosave.toml.abc.tmp", folder / ".autosave.toml.def.tmp"
    stale.write_text("half")
    live.write_text("half")
    old = time.time() - 2 * session_mod.STALE_TEMPORARY_S
    os.utime(stale, (old, old))
    assert load_session()
    assert not stale.exists() and live.exists()


# ---------------------------------------------------------------- two writers, kill -9

WRITER = r"""
import sys
from shadelab.scene.preset import load_preset
from shadelab.lab.session import save_session
tag, count = sys.argv[1], int(sys.argv[2])
scene = load_preset("cornell")
for i in range(count):
    scene.description = f"{tag} {i}"          # the scene names its writer ...
    scene.name = tag
    save_session(scene, f"source-{tag}")      # ... and so does the metadata
print("done", flush=True)
"""


def _consistent(result) -> bool:
    tag = result.source.removeprefix("source-")
    return result.scene.name == tag and result.scene.description.startswith(tag + " ")


def test_two_viewers_autosaving_at_once_never_pair_one_scene_with_the_others_metadata():
    a_valid_session()
    env = dict(os.environ)
    writers = [subprocess.Popen([sys.executable, "-c", WRITER, tag, "150"], env=env,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
               for tag in ("A", "B")]
    seen = set()
    reads = 0
    while any(w.poll() is None for w in writers):
        result = load_session()
        assert result.note == "" and result, result.note   # never a damaged or torn file
        if result.source != "cornell":
            assert _consistent(result), (result.source, result.scene.description)
            seen.add(result.source)
        reads += 1
    for w in writers:
        out, err = w.communicate(timeout=60)
        assert w.returncode == 0 and "done" in out, err
    assert reads > 5 and seen                       # the reader did overlap the writers
    final = load_session()
    assert final and _consistent(final) and final.scene.description.endswith(" 149")
    assert not damaged_copies()
    assert not list(autosave_path().parent.glob(".autosave.toml.*.tmp"))  # no stray files


def test_kill_9_during_autosaves_leaves_a_whole_session():
    a_valid_session()
    for attempt in range(4):
        writer = subprocess.Popen([sys.executable, "-c", WRITER, f"K{attempt}", "100000"],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        deadline = time.time() + 30
        while load_session().source in ("cornell", f"source-K{attempt - 1}") \
                and time.time() < deadline:
            time.sleep(0.02)                        # it is writing now
        time.sleep(0.05 * attempt)
        writer.send_signal(signal.SIGKILL)
        writer.wait(10)
        result = load_session()
        assert result and result.note == "" and _consistent(result)
        assert result.source == f"source-K{attempt}"
    assert not damaged_copies()


# ---------------------------------------------------------------- the viewer starts anyway


def test_the_viewer_starts_from_the_preset_and_shows_the_damage_in_the_status_line(
        monkeypatch, capsys):
    from shadelab.cli import view

    a_valid_session()
    autosave_path().write_bytes(b"null")
    captured = {}
    monkeypatch.setattr(view, "check_display", lambda: None)
    monkeypatch.setattr("shadelab.ui.app.run_viewer",
                        lambda state, options: captured.setdefault("state", state) and 0)
    assert view.run_view(_view_args()) == 0
    state = captured["state"]
    assert "damaged" in state.error and damaged_copies()[0].name in state.error
    assert state.source == view.DEFAULT_PRESET
    assert "damaged" in capsys.readouterr().err


def test_a_restored_mesh_that_no_longer_loads_falls_back_to_the_preset(tmp_path, monkeypatch):
    from shadelab.cli import view

    (tmp_path / "m.obj").write_text(TETRA)
    scene = load_preset("cornell")
    scene.base_dir = str(tmp_path)
    scene.objects.append(Object(shape="mesh", path="m.obj", material="white"))
    save_session(scene, "cornell")
    (tmp_path / "m.obj").write_bytes(b"v nan nan nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    captured = {}
    monkeypatch.setattr(view, "check_display", lambda: None)
    monkeypatch.setattr("shadelab.ui.app.run_viewer",
                        lambda state, options: captured.setdefault("state", state) and 0)
    assert view.run_view(_view_args()) == 0
    state = captured["state"]
    assert "does not load" in state.error and len(damaged_copies()) == 1
    assert all(o.path != "m.obj" for o in state.scene.objects)


def _view_args() -> argparse.Namespace:
    from shadelab.cli import build_parser

    return build_parser().parse_args(["view", "--frames", "1"])


def test_shadelab_view_under_xvfb_starts_with_a_damaged_session(tmp_path):
    if shutil.which("Xvfb") is None:
        pytest.skip("Xvfb is not installed: this test needs a display")
    a_valid_session()
    bad = b'[session]\nformat = 1\nsource = "cornell"\n[scene]\nschema_version = 1\nIa = ['
    autosave_path().write_bytes(bad)
    read_fd, write_fd = os.pipe()
    xvfb = subprocess.Popen(["Xvfb", "-displayfd", str(write_fd), "-screen", "0", "800x600x24",
                             "-nolisten", "tcp"], pass_fds=(write_fd,),
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(write_fd)
    try:
        import select

        ready, _, _ = select.select([read_fd], [], [], 20.0)
        number = os.read(read_fd, 64).decode().strip() if ready else ""
        if not number:
            pytest.skip("Xvfb did not start")
        env = dict(os.environ, DISPLAY=f":{number}")
        out = subprocess.run([sys.executable, "-m", "shadelab", "view", "--frames", "3",
                              "--window", "640x480"], env=env, capture_output=True, text=True,
                             timeout=120)
    finally:
        xvfb.terminate()
        xvfb.wait(10)
        os.close(read_fd)
    assert out.returncode == 0, out.stderr[-2000:]
    assert "Traceback" not in out.stderr
    copies = damaged_copies()
    assert len(copies) == 1 and copies[0].read_bytes() == bad
    assert copies[0].name in out.stderr and "damaged" in out.stderr
    restarted = load_session()          # the viewer's own autosave is a whole, new session
    assert not restarted or restarted.note == ""
