"""Every shipped preset loads; bad presets and bad flags give one line and exit code 2."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from shadelab.cli import main
from shadelab.errors import ShadeLabError
from shadelab.scene.preset import (
    list_presets,
    load_preset,
    save_preset,
    scene_to_dict,
)

PRESETS = list_presets()


@pytest.mark.parametrize("name", PRESETS)
def test_preset_loads_and_round_trips(name, tmp_path):
    scene = load_preset(name)
    assert scene.objects and scene.description
    path = tmp_path / f"{name}.toml"
    save_preset(scene, path)
    again = load_preset(str(path))
    assert _with_resolved_files(again) == _with_resolved_files(scene)


def _with_resolved_files(scene) -> dict:
    """scene_to_dict with mesh and image paths resolved: a preset saved elsewhere names the
    same files by other relative paths (save_preset rebases them)."""
    data = scene_to_dict(scene)

    def full(value: str) -> str:
        return str((Path(scene.base_dir) / value).resolve()) if value else value

    for obj in data["objects"]:
        obj["path"] = full(obj["path"])
    for m in data["materials"].values():
        m["texture"] = m["texture"] if m["texture"] == "checker" else full(m["texture"])
        m["bump"] = m["bump"] if m["bump"] == "bumps" else full(m["bump"])
    return data


def test_cornell_matches_published_data():
    scene = load_preset("cornell")
    assert len(scene.objects) == 19
    assert scene.camera.eye == (278.0, 273.0, -800.0)
    assert scene.camera.fov_y == pytest.approx(2 * math.degrees(math.atan(12.5 / 35)), abs=1e-3)
    assert scene.materials["white"].Od == (0.735, 0.736, 0.736)
    assert scene.materials["red"].kd == 1.0
    light = scene.lights[0]
    np.testing.assert_allclose(light.Ip, np.array([20.71, 10.85, 2.77]) * 130 * 105, rtol=2e-3)
    assert scene.materials["light"].emission == (20.71, 10.85, 2.77)


def test_set_override_reads_like_the_slides():
    scene = load_preset("cornell", ["materials.white.kd=0.5", "lights.0.Ip=2,2,2",
                                    "render.shading=gouraud"])
    assert scene.materials["white"].kd == 0.5
    assert scene.lights[0].Ip == (2.0, 2.0, 2.0)
    assert scene.render.shading == "gouraud"


def _write(tmp_path: Path, text: str) -> str:
    path = tmp_path / "bad.toml"
    path.write_text(text)
    return str(path)


GOOD = """schema_version = 1
[materials.m]
kd = 0.5
[[objects]]
shape = "sphere"
material = "m"
"""

BAD_PRESETS = {
    "syntax": ("schema_version = 1\n[camera\n", "TOML syntax error"),
    "unknown key": (GOOD + "shininess = 3\n", "unknown key 'objects.0.shininess'"),
    "wrong type": (GOOD.replace("kd = 0.5", 'kd = "high"'), "materials.m.kd"),
    "nan": (GOOD.replace("kd = 0.5", "kd = nan"), "not finite"),
    "negative": (GOOD.replace("kd = 0.5", "kd = -0.1"), "expected a number in [0, 1]"),
    "reflectance above 1": (GOOD.replace("kd = 0.5", "kd = 0.5\nOd = [1.2, 0.5, 0.5]"),
                            "materials.m.Od': expected three numbers in [0, 1]"),
    "version": (GOOD.replace("schema_version = 1", "schema_version = 7"), "schema_version"),
    "material": (GOOD.replace('material = "m"', 'material = "x"'), "objects.0.material"),
    "missing mesh": (GOOD.replace('shape = "sphere"', 'shape = "mesh"\npath = "no.obj"'),
                     "not found"),
}


@pytest.mark.parametrize("case", sorted(BAD_PRESETS))
def test_bad_preset_one_line_exit_2(case, tmp_path, capsys):
    text, expected = BAD_PRESETS[case]
    path = _write(tmp_path, text)
    code = main(["validate", path])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and "Traceback" not in err
    assert expected in err
    assert "bad.toml" in err or "no.obj" in err  # the file is named


def _mesh_preset(tmp_path: Path, filename: str, content: str | bytes) -> str:
    target = tmp_path / filename
    target.write_bytes(content if isinstance(content, bytes) else content.encode())
    mesh = f'shape = "mesh"\npath = "{filename}"'
    return _write(tmp_path, GOOD.replace('shape = "sphere"', mesh))


@pytest.mark.parametrize("filename,content,expected", [
    ("notes.txt", "hello", "is not a mesh file"),
    ("empty.obj", "# nothing here\n", "empty mesh"),
    ("degenerate.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 4 4 1\n", "degenerate"),
    ("garbage.stl", b"\x00\x01garbage" * 3, "mesh"),
])
def test_bad_mesh_files(tmp_path, capsys, filename, content, expected):
    path = _mesh_preset(tmp_path, filename, content)
    assert main(["validate", path]) == 2
    err = capsys.readouterr().err
    assert expected in err and err.count("\n") == 1 and "objects.0.path" in err


def test_good_mesh_file_loads(tmp_path):
    import trimesh

    trimesh.creation.box().export(tmp_path / "box.ply")
    path = _write(tmp_path, GOOD.replace('shape = "sphere"', 'shape = "mesh"\npath = "box.ply"'))
    from shadelab.geometry.mesh import scene_meshes

    meshes = scene_meshes(load_preset(path))
    assert len(meshes[0].faces) == 12


@pytest.mark.parametrize("argv,expected", [
    (["render", "cornell", "-o", "x.png", "--size", "0x10"], "--size"),
    (["render", "cornell", "-o", "x.png", "--size", "big"], "expected WxH"),
    (["render", "cornell", "-o", "x.png", "--set", "materials.nope.kd=1"], "materials.nope"),
    (["render", "cornell", "-o", "x.png", "--set", "kd"], "KEY=VALUE"),
    (["render", "cornell", "-o", "x.png", "--set", "lights.5.Ip=1,1,1"], "index below 1"),
    (["render", "cornell", "-o", "/no/such/dir/x.png"], "does not exist"),
    (["render", "no-such-preset", "-o", "x.png"], "unknown preset"),
    (["render", "cornell", "-o", "x.png", "--shading", "toon"], "invalid choice"),
])
def test_bad_cli_input(argv, expected, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert expected in err and err.count("\n") == 1


def test_unwritable_output(capsys):
    # /proc refuses new files even for root, so this holds on CI too
    assert main(["render", "cornell", "-o", "/proc/shadelab-test.png", "--size", "8x8"]) == 2
    err = capsys.readouterr().err
    assert "not writable" in err and err.count("\n") == 1


def test_directory_as_output_is_refused(tmp_path, capsys):
    assert main(["render", "cornell", "-o", str(tmp_path), "--size", "8x8"]) == 2
    assert "is a folder" in capsys.readouterr().err


def test_existing_output_is_not_truncated_by_the_check(tmp_path):
    from shadelab.imageio import check_writable

    keep = tmp_path / "mine.png"
    keep.write_bytes(b"user data")
    check_writable(str(keep), "-o")
    assert keep.read_bytes() == b"user data"


def test_error_type_is_one_line():
    with pytest.raises(ShadeLabError) as info:
        load_preset("definitely-missing")
    assert "\n" not in str(info.value)


def test_schema_json_is_generated_from_the_model():
    from shadelab.resources import presets_dir
    from shadelab.scene.schema import schema_text

    committed = (presets_dir() / "schema.json").read_text()
    assert committed == schema_text(), "run: python -m shadelab.scene.schema > presets/schema.json"
