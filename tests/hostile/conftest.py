"""Issue 24 (hostile input, round two): helpers that run the real ``shadelab`` CLI in a
subprocess and check the contract: the exit code, at most three lines on stderr, no traceback,
the inputs unchanged, no file left behind."""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
from pathlib import Path

import pytest

APP = Path(__file__).resolve().parents[2] / "app"


def env(tmp_path: Path) -> dict:
    """The CLI's environment: its own HOME (no autosaved session), the inherited PYTHONPATH
    kept, the app folder first."""
    e = dict(os.environ)
    e["PYTHONPATH"] = os.pathsep.join(p for p in (str(APP), e.get("PYTHONPATH", "")) if p)
    e["HOME"] = str(tmp_path / "home")
    e["SHADELAB_AUTOWARM"] = "0"
    (tmp_path / "home").mkdir(exist_ok=True)
    return e


def checksums(paths) -> dict:
    return {str(p): hashlib.sha256(Path(p).read_bytes()).hexdigest() for p in paths}


@pytest.fixture
def shadelab(tmp_path):
    """``shadelab(*args, code=2, timeout=..., xvfb=False)`` -> stderr, after asserting the
    exit code, at most 3 stderr lines and no traceback."""
    def run(*args: str, code: int = 2, timeout: float = 120, xvfb: bool = False,
            cwd: Path | None = None) -> str:
        cmd = [sys.executable, "-m", "shadelab", *args]
        if xvfb:
            cmd = ["xvfb-run", "-a", *cmd]
        out = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout,
                             env=env(tmp_path), cwd=cwd or tmp_path, stdin=subprocess.DEVNULL)
        err = out.stderr
        assert out.returncode == code, (out.returncode, err[-2000:])
        assert "Traceback" not in err, err[-2000:]
        if code:
            assert 1 <= len(err.strip().splitlines()) <= 3, err
        return err
    return run
