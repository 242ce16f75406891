"""Issue 24, item 5: unbounded meshes. One face repeated 300,000 times or one polygon of
100,000 vertices (fanned from a corner) is refused with one line naming the figure and its
limit (limits.MAX_VERTEX_FACES), not a MemoryError from the normals' k x k comparison."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from conftest import checksums
from shadelab import limits

PRESET = """schema_version = 1
[materials.m]
kd = 0.5
[[lights]]
position = [0.0, 5.0, 3.0]
[camera]
eye = [0.0, 0.0, 4.0]
target = [0.0, 0.0, 0.0]
[[objects]]
shape = "mesh"
path = "{name}"
material = "m"
"""


def repeated_face(path: Path, copies: int) -> None:
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n" + "f 1 2 3\n" * copies)


def polygon(path: Path, corners: int) -> None:
    lines = [f"v {math.cos(2 * math.pi * i / corners):.7f} "
             f"{math.sin(2 * math.pi * i / corners):.7f} 0" for i in range(corners)]
    lines.append("f " + " ".join(str(i + 1) for i in range(corners)))
    path.write_text("\n".join(lines) + "\n")


@pytest.mark.parametrize("make, count", [(repeated_face, 300_000), (polygon, 100_000),
                                         (polygon, limits.MAX_VERTEX_FACES + 10)])
def test_a_mesh_fan_over_the_budget_is_one_line(shadelab, tmp_path, make, count):
    mesh = tmp_path / "m.obj"
    make(mesh, count)
    (tmp_path / "p.toml").write_text(PRESET.format(name="m.obj"))
    before = checksums([mesh, tmp_path / "p.toml"])
    err = shadelab("render", "p.toml", "-o", "out.png", "--size", "32x24", timeout=180)
    assert "triangles at a vertex" in err and "over the limit of" in err, err
    assert "m.obj" in err and err.count("\n") == 1
    assert not (tmp_path / "out.png").exists()
    assert checksums([mesh, tmp_path / "p.toml"]) == before


def test_a_polygon_within_the_budget_renders(shadelab, tmp_path):
    polygon(tmp_path / "m.obj", 500)
    (tmp_path / "p.toml").write_text(PRESET.format(name="m.obj"))
    shadelab("render", "p.toml", "-o", "out.png", "--size", "32x24", code=0, timeout=180)
    assert (tmp_path / "out.png").stat().st_size > 0
