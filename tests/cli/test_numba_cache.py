"""The first run is as fast as the tenth (issue 20, item 6): numba's kernel cache lives in the
user's cache folder (``$XDG_CACHE_HOME/shadelab/numba``, an existing NUMBA_CACHE_DIR kept),
never in the package; an unwritable folder is one line and a fallback; the first CLI use with
a cold cache starts ``shadelab warm`` in the background, once."""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

import shadelab
from shadelab.cli import main

PACKAGE = Path(shadelab.__file__).resolve().parent

KERNEL = """
import numpy as np, shadelab, os
from shadelab.radiosity.solvers import solve_gauss_seidel
F = np.array([[0.0, 0.5], [0.5, 0.0]]); rho = np.full((2, 3), 0.5); E = np.ones((2, 3))
list(solve_gauss_seidel(F, rho, E, iterations=2))
import numba.core.config as c
print(c.CACHE_DIR)
"""


def _fresh_env(tmp_path: Path, **extra: str) -> dict:
    env = {k: v for k, v in os.environ.items()
           if k not in ("NUMBA_CACHE_DIR", "SHADELAB_CACHE_DIR", "XDG_CACHE_HOME")}
    env["TMPDIR"] = str(tmp_path / "tmp")
    (tmp_path / "tmp").mkdir(exist_ok=True)
    env.update(extra)
    return env


def _cache_files(folder: Path, newer_than: float = 0.0) -> list[Path]:
    return [p for p in folder.rglob("*") if p.suffix in (".nbi", ".nbc")
            and p.stat().st_mtime >= newer_than]


def test_a_fresh_process_writes_its_kernels_to_the_user_cache_not_the_package(tmp_path):
    start = time.time() - 1
    xdg = tmp_path / "xdg"
    run = subprocess.run([sys.executable, "-c", KERNEL], env=_fresh_env(tmp_path,
                         XDG_CACHE_HOME=str(xdg)), capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    folder = xdg / "shadelab" / "numba"
    assert run.stdout.strip() == str(folder)
    written = _cache_files(folder)
    assert any(p.suffix == ".nbi" for p in written) and any(p.suffix == ".nbc" for p in written)
    assert all("solvers" in p.name for p in written)
    assert _cache_files(PACKAGE, newer_than=start) == []       # nothing into the package


def test_an_existing_numba_cache_dir_is_respected(tmp_path):
    mine = tmp_path / "mine"
    code = "import shadelab, os; print(os.environ['NUMBA_CACHE_DIR'])"
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=_fresh_env(tmp_path, NUMBA_CACHE_DIR=str(mine),
                                        XDG_CACHE_HOME=str(tmp_path / "xdg")), timeout=120)
    assert run.stdout.strip() == str(mine)


def test_an_unwritable_cache_folder_is_one_line_and_a_fallback(tmp_path):
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("x")
    env = _fresh_env(tmp_path, XDG_CACHE_HOME=str(blocker), SHADELAB_AUTOWARM="0")
    run = subprocess.run([sys.executable, "-m", "shadelab", "presets"], env=env,
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0 and "lecture" in run.stdout
    fallback = tmp_path / "tmp" / f"shadelab-numba-{os.getuid()}"
    lines = run.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("note: numba cache folder"), run.stderr
    assert str(fallback) in lines[0] and "Traceback" not in run.stderr
    quiet = subprocess.run([sys.executable, "-m", "shadelab", "-q", "presets"], env=env,
                           capture_output=True, text=True, timeout=120)
    assert quiet.returncode == 0 and quiet.stderr == ""
    kernel = subprocess.run([sys.executable, "-c", KERNEL], env=env, capture_output=True,
                            text=True, timeout=300)
    assert kernel.returncode == 0 and kernel.stdout.strip() == str(fallback), kernel.stderr
    assert _cache_files(fallback)


class _Spawned:
    def __init__(self):
        self.calls = []

    def __call__(self, argv, **kwargs):
        self.calls.append((argv, kwargs))


def test_first_cli_use_starts_warm_in_the_background_once(tmp_path, monkeypatch, capsys):
    from shadelab.cli import warm

    spawned = _Spawned()
    monkeypatch.setattr(warm.subprocess, "Popen", spawned)
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "numba"))
    monkeypatch.setenv("SHADELAB_AUTOWARM", "1")
    assert main(["presets"]) == 0
    assert len(spawned.calls) == 1
    argv, kwargs = spawned.calls[0]
    assert argv[-3:] == ["shadelab", "warm", "--quiet"] and kwargs["start_new_session"]
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "in the background" in err[0] and str(tmp_path / "numba") in err[0]
    assert main(["presets"]) == 0                  # started a moment ago: not again
    assert len(spawned.calls) == 1 and capsys.readouterr().err == ""
    mark = warm.done_mark()
    mark.with_suffix(".started").unlink()
    mark.write_text("done")                          # a finished warm-up: never again
    assert main(["presets"]) == 0 and len(spawned.calls) == 1
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "other"))
    monkeypatch.setenv("SHADELAB_AUTOWARM", "0")   # turned off (the tests' own setting)
    assert main(["presets"]) == 0 and len(spawned.calls) == 1


def test_warm_leaves_its_done_mark(tmp_path, monkeypatch, capsys):
    from shadelab.cli import warm
    from shadelab.lab import pipeline_jobs

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "numba"))
    monkeypatch.setattr(warm, "warm_meshes", lambda: 0)
    monkeypatch.setattr(pipeline_jobs, "warm_kernels", lambda scene, size: iter(()))
    assert not warm.done_mark().exists()
    assert main(["warm", "--quiet"]) == 0
    assert warm.done_mark().exists() and capsys.readouterr().err == ""


@pytest.mark.parametrize("name", ["numba.core.config"])
def test_the_tests_own_cache_is_not_the_users(name):
    assert "shadelab-test-numba" in os.environ["NUMBA_CACHE_DIR"]
    config = sys.modules.get(name)
    if config is not None:
        assert "shadelab-test-numba" in config.CACHE_DIR


def test_dist_version_reads_what_importlib_metadata_reads():
    """The kernel cache's stamp and the mesh cache's key read package versions without
    importing importlib.metadata (a slow import on the viewer's way to its first frame)."""
    from importlib.metadata import version

    from shadelab.distributions import dist_version

    for name in ("numba", "trimesh", "numpy", "moderngl"):
        assert dist_version(name) == version(name), name
    assert dist_version("no_such_package_shadelab") is None
