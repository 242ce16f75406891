"""shadelab sweep: GIF, MP4 and PNG folders, frames equal to renders, grid, refusals (exit 2)."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image as PILImage

import shadelab
from shadelab.cli import main
from shadelab.cli.sweep import frame_values


def test_frame_values_closed_form():
    assert frame_values(0.0, 1.0, 5, False) == [0.0, 0.25, 0.5, 0.75, 1.0]
    assert frame_values(1.0, 3.0, 5, True) == [1, 2, 2, 2, 3]  # round half to even
    assert frame_values(0.3, 0.9, 1, False) == [0.3]


@pytest.mark.gl
def test_png_frames_are_the_renders(gl_ctx, tmp_path):
    out = tmp_path / "frames"
    assert main(["sweep", "lecture", "materials.floor.kd=0:1", "--frames", "3", "--size",
                 "40x30", "-o", str(out), "--no-caption"]) == 0
    names = sorted(p.name for p in out.iterdir())
    assert names == ["frame_0000.png", "frame_0001.png", "frame_0002.png"]
    for name, kd in zip(names, (0, 0.5, 1), strict=True):
        scene = shadelab.load_preset("lecture", {"materials.floor.kd": kd})
        expected = shadelab.render(scene, size=(40, 30)).to_srgb8()
        np.testing.assert_array_equal(np.asarray(PILImage.open(out / name)), expected)


@pytest.mark.gl
def test_gif_with_caption_and_mp4_grid(gl_ctx, tmp_path):
    gif = tmp_path / "kd.gif"
    assert main(["sweep", "lecture", "materials.floor.kd=0:1", "--frames", "4", "--size",
                 "64x48", "-o", str(gif)]) == 0
    with PILImage.open(gif) as im:
        assert im.n_frames == 4 and im.size == (64, 48)
        im.seek(0)
        first = np.asarray(im.convert("RGB")).copy()
        im.seek(3)
        last = np.asarray(im.convert("RGB")).copy()
    assert np.abs(first.astype(int) - last).mean() > 1.0  # kd changes the floor
    for caption in ([], ["--no-caption"]):
        assert main(["sweep", "lecture", "materials.floor.kd=0:0", "--frames", "1", "--size",
                     "64x48", "-o", str(tmp_path / f"c{len(caption)}"), *caption]) == 0
    with_text = np.asarray(PILImage.open(tmp_path / "c0" / "frame_0000.png")).astype(int)
    plain = np.asarray(PILImage.open(tmp_path / "c1" / "frame_0000.png")).astype(int)
    np.testing.assert_array_equal(with_text[:24], plain[:24])  # the caption sits at the foot
    assert np.abs(with_text[-6:, :20] - plain[-6:, :20]).max() > 100
    import imageio_ffmpeg

    mp4 = tmp_path / "n.mp4"
    assert main(["sweep", "lecture", "objects.1.subdivisions=1:3", "--frames", "3", "--size",
                 "33x25", "--grid", "-o", str(mp4)]) == 0
    frames = imageio_ffmpeg.read_frames(str(mp4))
    meta = next(frames)
    assert meta["size"] == (100, 26)  # three 33-pixel tiles, padded to even sides
    assert sum(1 for _ in frames) == 3


@pytest.mark.parametrize("args, message", [
    (["materials.floor.kd=a:b"], "FROM and TO must be numbers"),
    (["materials.floor.kd=0..1"], "expected KEY=FROM:TO"),
    (["materials.floor.kd=0:2"], "expected a number in [0, 1], got 2"),
    (["materials.nope.kd=0:1"], "no such key"),
    (["materials.floor.Od=0:1"], "reflectance color"),
    (["render.shading=0:1"], "expected"),
    (["objects.1.subdivisions=0.5:3"], "expected an integer in [0, 7]"),
    (["objects.1.subdivisions=1:2.5"], "expected integer ends"),
    (["materials.floor.kd=0:1", "--frames", "0"], "--frames 0"),
    (["materials.floor.kd=0:1", "--pipeline", "toon"], "--pipeline 'toon'"),
    (["materials.floor.kd=0:1", "--grid", "--pipeline", "raytrace"], "--grid and --shading"),
    (["materials.floor.kd=0:1", "-o", "x.avi"], "expected OUT.gif, OUT.mp4 or a folder"),
])
def test_bad_sweeps_exit_2_with_one_line(tmp_path, capsys, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)
    argv = ["sweep", "lecture", *args]
    if "-o" not in args:
        argv += ["-o", "out.gif"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("shadelab: error: ") and err.count("\n") == 1 and message in err
    assert list(tmp_path.iterdir()) == []  # nothing written


def test_a_folder_with_files_is_not_overwritten(tmp_path, capsys):
    folder = tmp_path / "mine"
    folder.mkdir()
    (folder / "notes.txt").write_text("keep")
    assert main(["sweep", "lecture", "materials.floor.kd=0:1", "-o", str(folder)]) == 2
    assert "new or empty folder" in capsys.readouterr().err
    assert (folder / "notes.txt").read_text() == "keep"


@pytest.mark.gl
def test_ctrl_c_leaves_nothing_half_written(gl_ctx, tmp_path, monkeypatch):
    from shadelab import api

    real, calls = api.render, []

    def interrupted(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(api, "render", interrupted)
    (tmp_path / "kd.gif").write_bytes(b"the user's old file")
    assert main(["sweep", "lecture", "materials.floor.kd=0:1", "--frames", "3", "--size",
                 "16x16", "-o", str(tmp_path / "kd.gif")]) == 130
    assert sorted(p.name for p in tmp_path.iterdir()) == ["kd.gif"]
    assert (tmp_path / "kd.gif").read_bytes() == b"the user's old file"


def test_a_truncated_video_is_an_error_not_a_result(gl_ctx, tmp_path, capsys):
    """On a full disk ffmpeg prints 'Error writing trailer' and exits 0, leaving a truncated
    file that replaced the output (issue 24, class 11): the frames written are counted first."""

    from shadelab.cli.sweep import _check_video

    good = tmp_path / "n.mp4"
    assert main(["sweep", "lecture", "materials.plastic.n=1:100", "--frames", "3", "--size",
                 "32x24", "-o", str(good)]) == 0
    _check_video(good, good, 3)                     # complete: no error
    cut = tmp_path / "cut.mp4"
    data = good.read_bytes()
    cut.write_bytes(data[: len(data) // 3])
    with pytest.raises(OSError, match=r"not completely written \(\d of 3 frames"):
        _check_video(cut, tmp_path / "out.mp4", 3)


def test_a_killed_sweeps_partial_output_is_removed_by_the_next(gl_ctx, tmp_path):
    """SIGKILL leaves the temporary output (no cleanup runs); the next sweep to the same
    target removes the stale ones of its own name and keeps a fresh one (a live writer's)."""
    import os
    import time

    from shadelab.cli.sweep import PARTIAL, STALE_S

    stale = tmp_path / f".n{PARTIAL}dead.mp4"
    fresh = tmp_path / f".n{PARTIAL}live.mp4"
    other = tmp_path / ".notes.txt"
    for path in (stale, fresh, other):
        path.write_bytes(b"x")
    old = time.time() - 2 * STALE_S
    os.utime(stale, (old, old))
    os.utime(other, (old, old))
    assert main(["sweep", "lecture", "materials.plastic.n=1:100", "--frames", "2", "--size",
                 "32x24", "-o", str(tmp_path / "n.mp4")]) == 0
    assert not stale.exists() and fresh.exists() and other.exists()
