"""Shared fixtures: the one headless GL context, a seeded RNG, golden-image comparison."""

from __future__ import annotations

import os
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings

# Property-based tests explore the same examples on every run: CI stays reproducible, and a
# new failure found while developing (set HYPOTHESIS_PROFILE=explore) is kept by hypothesis.
settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
settings.register_profile("explore", deadline=None, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

# The mesh cache (shadelab.geometry.cache) of this test run: shared by its tests and the
# viewers they start, never the user's own ~/.cache
os.environ["SHADELAB_CACHE_DIR"] = tempfile.mkdtemp(prefix="shadelab-test-cache-")
# numba's kernel cache of the tests: not the user's (shadelab sets NUMBA_CACHE_DIR at import),
# kept between runs so the suite compiles its kernels once; no background warm-up is started
os.environ["NUMBA_CACHE_DIR"] = os.path.join(
    tempfile.gettempdir(), f"shadelab-test-numba-{os.getuid() if hasattr(os, 'getuid') else 0}")
os.environ["SHADELAB_AUTOWARM"] = "0"
assert "numba" not in sys.modules, "numba was imported before its test cache folder was set"

ROOT = Path(__file__).resolve().parent.parent
# Tests live in one folder per layer (tests/scene, tests/raster, ...); their shared helpers
# (golden.py, gui_harness.py) stay here, importable from every folder.
sys.path.insert(0, str(Path(__file__).resolve().parent))
GOLDEN_DIR = Path(__file__).resolve().parent / "golden"
OUTPUT_DIR = Path(__file__).resolve().parent / "_output"


def pytest_addoption(parser):
    parser.addoption("--update-golden", action="store_true",
                     help="regenerate golden images instead of comparing")


@pytest.fixture(scope="session")
def gl_ctx():
    """The process's headless EGL context (this is the only place tests get one)."""
    from shadelab.errors import ShadeLabError
    from shadelab.gl.context import headless_context

    try:
        ctx = headless_context()
    except ShadeLabError as exc:
        pytest.skip(f"no EGL: {exc}")
    _ = ctx.error
    yield ctx


@pytest.fixture(autouse=True)
def _gl_errors_checked(request):
    """Every test that used the GL context leaves it without an error (as moderngl's conftest):
    an error is read before the test (a fault of whoever left it) and after (this test's)."""
    if "gl_ctx" not in request.fixturenames:
        yield
        return
    ctx = request.getfixturevalue("gl_ctx")
    before = ctx.error
    assert before == "GL_NO_ERROR", f"a GL error was left before this test: {before}"
    yield
    after = ctx.error
    assert after == "GL_NO_ERROR", f"this test left a GL error: {after}"


@pytest.fixture
def np_rng():
    return np.random.default_rng(20261122)


@pytest.fixture
def update_golden(request) -> bool:
    return bool(request.config.getoption("--update-golden"))


@pytest.fixture(autouse=True)
def _isolated_state(tmp_path, monkeypatch):
    """Keep autosaves and other user state of tests out of the real home."""
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
