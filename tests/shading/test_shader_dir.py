"""The shader folder is found one way (shadelab.resources.shaders_dir), in a checkout and in
an installed wheel's layout, and no other module builds a path to it."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import shadelab
from shadelab.resources import shaders_dir

PACKAGE = Path(shadelab.__file__).resolve().parent


def test_checkout_finds_the_top_level_shaders_folder():
    root = PACKAGE.parent.parent  # app/shadelab -> the repository
    assert shaders_dir() == root / "shaders"
    assert (shaders_dir() / "include" / "lighting.glsl").is_file()


def test_wheel_layout_finds_the_shaders_inside_the_package(tmp_path):
    """A wheel puts shaders/ in the package (pyproject's force-include): that copy is used."""
    package = tmp_path / "site" / "shadelab"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("")
    shutil.copy(PACKAGE / "resources.py", package / "resources.py")
    (package / "shaders" / "include").mkdir(parents=True)
    (package / "shaders" / "include" / "lighting.glsl").write_text("// wheel\n")
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(
        [str(tmp_path / "site"), *filter(None, [env.get("PYTHONPATH")])])
    run = subprocess.run([sys.executable, "-c",
                          "from shadelab.resources import shaders_dir; print(shaders_dir())"],
                         capture_output=True, text=True, env=env, cwd=tmp_path, timeout=60)
    assert run.returncode == 0, run.stderr
    assert Path(run.stdout.strip()) == package / "shaders"


def test_no_other_module_builds_the_shader_path():
    """Only resources.py names the folder; the program loader and the rest call it."""
    pattern = re.compile(r"""["']shaders["']""")
    offenders = [str(p.relative_to(PACKAGE)) for p in PACKAGE.rglob("*.py")
                 if p.name != "resources.py" and pattern.search(p.read_text())]
    assert offenders == []
