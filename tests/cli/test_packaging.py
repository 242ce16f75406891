"""A wheel built from the repository carries its shaders and presets and renders from anywhere."""

from __future__ import annotations

import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.slow
@pytest.mark.gl
def test_wheel_renders_from_any_directory(tmp_path):
    wheels = tmp_path / "wheels"
    build = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w",
                            str(wheels), str(ROOT)], capture_output=True, text=True)
    if build.returncode != 0 and "hatchling" in build.stderr and "No matching" in build.stderr:
        pytest.skip("hatchling is not reachable to build the wheel")
    assert build.returncode == 0, build.stderr
    (wheel,) = wheels.glob("shadelab-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    assert "shadelab/shaders/include/lighting.glsl" in names
    assert "shadelab/presets/cornell.toml" in names
    site = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target",
                    str(site), str(wheel)], check=True, capture_output=True)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = {**os.environ, "PYTHONPATH": str(site)}
    out = subprocess.run([sys.executable, "-c",
                          "import shadelab, sys; from shadelab.cli import main; "
                          "print(shadelab.__file__); "
                          "sys.exit(main(['render', 'cornell', '-o', 'x.png', "
                          "'--size', '32x32']))"],
                         cwd=elsewhere, env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.splitlines()[0].startswith(str(site))  # the wheel's copy, not the repo's
    assert (elsewhere / "x.png").stat().st_size > 100


@pytest.mark.slow
def test_sdist_builds_and_carries_what_a_release_needs(tmp_path):
    """The sdist (python -m build --sdist) holds the sources, the license and the changelog,
    and its version is the package's __version__ (one place)."""
    import tarfile

    import shadelab

    build = subprocess.run([sys.executable, "-m", "build", "--sdist", "--no-isolation",
                            "--outdir", str(tmp_path), str(ROOT)], capture_output=True,
                           text=True)
    assert build.returncode == 0, build.stderr[-3000:]
    (sdist,) = tmp_path.glob("shadelab-*.tar.gz")
    assert sdist.name == f"shadelab-{shadelab.__version__}.tar.gz"
    with tarfile.open(sdist) as tar:
        names = {name.split("/", 1)[1] for name in tar.getnames() if "/" in name}
    for needed in ("LICENSE", "CHANGELOG.md", "README.md", "pyproject.toml",
                   "app/shadelab/__init__.py", "app/shadelab/api.py", "shaders/phong.frag",
                   "presets/cornell.toml", "examples/quickstart.py"):
        assert needed in names, needed


def test_version_has_one_source():
    import tomllib

    import shadelab
    from shadelab.cli import main

    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert "version" not in project and "version" in project["dynamic"]
    out = subprocess.run([sys.executable, "-m", "shadelab", "--version"], capture_output=True,
                         text=True)
    assert out.returncode == 0 and out.stdout.strip() == f"shadelab {shadelab.__version__}"
    assert "bench" in project["optional-dependencies"]
    assert callable(main)
    from importlib.metadata import entry_points

    assert any(e.value == "shadelab.testing" for e in entry_points(group="pytest11"))
