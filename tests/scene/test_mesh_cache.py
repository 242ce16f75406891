"""The on-disk mesh cache (shadelab.geometry.cache): a viewer reopening a preset builds its
meshes and shadow-volume silhouettes without importing trimesh; what comes out of the cache
is exactly what trimesh made; a damaged or foreign entry is rebuilt, never an error."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from shadelab.geometry import cache
from shadelab.geometry.mesh import _local_mesh
from shadelab.geometry.silhouette import closed_caster
from shadelab.scene import load_preset

ROOT = Path(__file__).resolve().parents[2]

FIRST_FRAME_WORK = """
import json, sys
from shadelab.scene import load_preset
from shadelab.geometry.mesh import scene_meshes
from shadelab.geometry.silhouette import light_homogeneous, shadow_volume
scene = load_preset("lecture")
light = scene.lights[0]
for mesh in scene_meshes(scene):
    shadow_volume(mesh.vertices, mesh.faces,
                  light_homogeneous(light.kind, light.position, light.direction))
print(json.dumps({"trimesh": "trimesh" in sys.modules, "scipy": "scipy" in sys.modules}))
"""


def _run(folder: Path) -> dict:
    env = dict(os.environ, SHADELAB_CACHE_DIR=str(folder), PYTHONPATH=str(ROOT / "app"))
    out = subprocess.run([sys.executable, "-c", FIRST_FRAME_WORK], env=env, text=True,
                         capture_output=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_the_second_run_builds_the_lecture_without_trimesh(tmp_path):
    assert _run(tmp_path) == {"trimesh": True, "scipy": True}       # cold: trimesh builds
    assert len(list((tmp_path / "meshes").glob("*.npz"))) >= 3
    assert _run(tmp_path) == {"trimesh": False, "scipy": False}     # warm: none of it


def test_cached_arrays_are_exactly_trimesh_s(monkeypatch, tmp_path):
    monkeypatch.setenv(cache.CACHE_ENV, str(tmp_path))
    scene = load_preset("lecture")
    for obj in scene.objects:
        if obj.shape in ("plane", "quad"):
            continue
        cold = _local_mesh(obj, ".", 0)
        warm = _local_mesh(obj, ".", 0)
        assert cold[3] is None and warm[3] is None  # primitives: no welded places
        for a, b in zip(cold[:3], warm[:3], strict=True):
            np.testing.assert_array_equal(a, b)
            assert a.dtype == b.dtype
    import trimesh

    box = trimesh.creation.box()
    fresh = closed_caster(box.vertices, box.faces)
    again = closed_caster(box.vertices, box.faces)
    for field in ("vertices", "faces", "face_adjacency", "face_adjacency_edges"):
        np.testing.assert_array_equal(getattr(fresh, field), getattr(again, field))
    # an open caster is remembered as open
    quad = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    assert closed_caster(quad, faces) is None and closed_caster(quad, faces) is None


@pytest.mark.parametrize("damage", [b"", b"not a zip file", b"PK\x03\x04broken"])
def test_a_damaged_entry_is_rebuilt(monkeypatch, tmp_path, damage):
    monkeypatch.setenv(cache.CACHE_ENV, str(tmp_path))
    obj = load_preset("lecture").objects[2]          # a sphere
    want = _local_mesh(obj, ".", 0)
    files = list((tmp_path / "meshes").glob("primitive-*.npz"))
    assert len(files) == 1
    files[0].write_bytes(damage)
    got = _local_mesh(obj, ".", 0)
    np.testing.assert_array_equal(got[1], want[1])
    assert files[0].stat().st_size > 100                 # written again


def test_a_foreign_entry_with_wrong_arrays_is_not_used(monkeypatch, tmp_path):
    monkeypatch.setenv(cache.CACHE_ENV, str(tmp_path))
    obj = load_preset("lecture").objects[2]
    want = _local_mesh(obj, ".", 0)
    path = next((tmp_path / "meshes").glob("primitive-*.npz"))
    np.savez(path, vertices=np.zeros((3, 3)), faces=np.array([[0, 1, 7]]))   # index past V
    np.testing.assert_array_equal(_local_mesh(obj, ".", 0)[1], want[1])


def test_keys_follow_every_input_and_the_cache_can_be_off(monkeypatch, tmp_path):
    a = cache.key("primitive", "sphere", 1.0, 3)
    assert a == cache.key("primitive", "sphere", 1.0, 3)
    assert a != cache.key("primitive", "sphere", 1.0, 4)
    assert cache.key("closed", np.zeros(3)) != cache.key("closed", np.zeros(3, np.float32))
    monkeypatch.setenv(cache.CACHE_ENV, "off")
    assert cache.cache_dir() is None
    cache.store("x", {"a": np.ones(2)})
    assert cache.load("x") is None
    monkeypatch.setenv(cache.CACHE_ENV, str(tmp_path / "ro"))
    (tmp_path / "ro").write_text("a file where the folder should be")
    cache.store("x", {"a": np.ones(2)})               # cannot write: ignored, no error
    assert cache.load("x") is None


def test_a_cache_entry_that_is_a_fifo_is_a_miss_not_a_hang(tmp_path, monkeypatch):
    """Issue 24, class 8: np.load opened a FIFO entry and waited for a writer forever."""
    import os
    import threading

    from shadelab.geometry import cache

    monkeypatch.setenv("SHADELAB_CACHE_DIR", str(tmp_path))
    folder = cache.cache_dir()
    folder.mkdir(parents=True, exist_ok=True)
    os.mkfifo(folder / "entry.npz")
    result = {}
    reader = threading.Thread(target=lambda: result.update(value=cache.load("entry")),
                              daemon=True)
    reader.start()
    reader.join(10.0)
    assert not reader.is_alive(), "cache.load hung on a FIFO"
    assert result["value"] is None
    cache.store("entry", {"a": np.arange(3)})   # the FIFO is replaced by a real entry
    assert (folder / "entry.npz").is_file()
    np.testing.assert_array_equal(cache.load("entry")["a"], np.arange(3))
