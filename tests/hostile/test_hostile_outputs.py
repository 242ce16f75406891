"""Issue 24, item 2: an output that is one of the run's inputs (preset, mesh, texture, bump
map, lesson) or a file shipped with ShadeLab is refused with one line, and nothing is written;
an output that cannot be written is one line, not a traceback."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from conftest import checksums
from shadelab.errors import ShadeLabError
from shadelab.resources import presets_dir

PRESETS = presets_dir()


@pytest.fixture(autouse=True)
def _shipped_files_restored():
    """These tests aim outputs at shipped files: should the guard ever fail, the shipped
    presets folder is put back as it was (and the test fails on its checksums)."""
    kept = {p: p.read_bytes() for p in PRESETS.rglob("*") if p.is_file()}
    yield
    for path in PRESETS.rglob("*"):
        if path.is_file() and path not in kept:
            path.unlink()
    for path, data in kept.items():
        if path.read_bytes() != data:
            path.write_bytes(data)


@pytest.fixture
def copies(tmp_path):
    """The mesh and surface-detail presets with their files, copied: the inputs are the
    user's own (not shipped) files."""
    for name in ("surface-detail.toml", "mesh-stl.toml", "cornell.toml"):
        shutil.copy(PRESETS / name, tmp_path / name)
    shutil.copytree(PRESETS / "textures", tmp_path / "textures")
    (tmp_path / "meshes").mkdir()
    shutil.copy(PRESETS / "meshes" / "ant.stl", tmp_path / "meshes" / "ant.stl")
    return tmp_path


def _files(folder: Path) -> set[str]:
    return {str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file()}


SHIPPED_TEXTURE = str(PRESETS / "textures" / "bricks.png")


@pytest.mark.parametrize("args, named", [
    (["render", "surface-detail.toml", "-o", "textures/bricks.png"], "texture"),
    (["render", "surface-detail.toml", "-o", "out.png", "--npy", "textures/bricks-height.png"],
     "bump map"),
    (["render", "mesh-stl.toml", "-o", "out.png", "--npy", "meshes/ant.stl"], "mesh"),
    (["raytrace", "surface-detail.toml", "--size", "32x24", "-o", "textures/bricks.png"],
     "texture"),
    (["render", "cornell.toml", "-o", SHIPPED_TEXTURE], "shipped"),
    (["render", "surface-detail", "-o", SHIPPED_TEXTURE], "texture"),
    (["sweep", "cornell.toml", "render.exposure=0.5:1", "--frames", "2", "-o", "cornell.toml"],
     "cornell.toml"),
])
def test_an_output_that_is_an_input_is_refused_and_nothing_changes(shadelab, copies, args,
                                                                   named):
    guarded = [*copies.rglob("*.toml"), *copies.rglob("*.png"), *copies.rglob("*.stl"),
               Path(SHIPPED_TEXTURE)]
    before, files = checksums(guarded), _files(copies)
    err = shadelab(*args, cwd=copies)
    assert err.count("\n") == 1 and named in err, err
    assert checksums(guarded) == before
    assert _files(copies) == files  # no output, no temporary file left behind


@pytest.mark.parametrize("args", [
    ["sweep", "cornell", "render.exposure=0.5:1", "--frames", "2", "-o", "/proc/self/x.gif"],
    ["sweep", "cornell", "render.exposure=0.5:1", "--frames", "2", "-o", "/proc/self/frames"],
    ["charts", "--out", "/proc/self", "--only", "shading", "--quick"],
    ["gallery", "--out", "/proc/self", "--only", "mach-bands"],
    ["gallery", "--out", str(PRESETS), "--only", "mach-bands"],
    ["bench", "--json", "/proc/self/x.json", "--quick", "--only", "raster"],
])
@pytest.mark.skipif(not Path("/proc/self").is_dir(), reason="needs Linux's /proc (a folder "
                    "no file can be made in)")
def test_an_output_that_cannot_be_written_is_one_line(shadelab, args):
    shadelab(*args, timeout=200)


def test_a_failed_write_is_one_line_exit_1(capsys, monkeypatch):
    import errno

    from shadelab import cli

    def full(args):
        raise OSError(errno.ENOSPC, "No space left on device", "out.gif")
    monkeypatch.setattr("shadelab.cli.sweep.run", full)
    code = cli.main(["sweep", "cornell", "render.exposure=0.5:1", "-o", "out.gif"])
    err = capsys.readouterr().err
    assert code == 1 and err.count("\n") == 1 and "out.gif" in err and "No space" in err


def test_save_preset_refuses_a_shipped_preset_and_the_scenes_texture(tmp_path, copies):
    from shadelab import api

    lecture = PRESETS / "lecture.toml"
    before = checksums([lecture, copies / "textures" / "bricks.png"])
    scene = api.load_preset("lecture")
    with pytest.raises(ShadeLabError, match="shipped with ShadeLab") as info:
        api.save_preset(scene, lecture)
    assert "\n" not in str(info.value)
    detail = api.load_preset(str(copies / "surface-detail.toml"))
    with pytest.raises(ShadeLabError, match="texture"):
        api.save_preset(detail, copies / "textures" / "bricks.png")
    assert checksums([lecture, copies / "textures" / "bricks.png"]) == before
    api.save_preset(scene, tmp_path / "mine.toml")  # anywhere else: written
    assert api.load_preset(str(tmp_path / "mine.toml")).lights


def test_image_save_refuses_a_shipped_file():
    from shadelab import api

    before = checksums([SHIPPED_TEXTURE])
    image = api.render("cornell", size=(16, 12))
    with pytest.raises(ShadeLabError, match="shipped"):
        image.save(SHIPPED_TEXTURE)
    assert checksums([SHIPPED_TEXTURE]) == before
