"""End to end: ``shadelab view --lesson ... --step 12 --frames K --bench-json F`` on the
Whitted step waits for that step's job and records its first image and end (issue 19 item 5;
before: null), under xvfb-run with a timeout."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
TIMEOUT = 300

pytestmark = pytest.mark.gui


@pytest.mark.skipif(shutil.which("xvfb-run") is None, reason="needs xvfb-run")
def test_lesson_offline_step_records_first_image_and_done(tmp_path):
    out = tmp_path / "bench.json"
    env = dict(os.environ, PYTHONPATH=str(ROOT / "app"))
    proc = subprocess.run(
        ["xvfb-run", "-a", sys.executable, "-m", "shadelab", "view",
         "--lesson", "phong-to-radiosity", "--step", "12", "--frames", "5",
         "--window", "640x480", "--no-autosave", "--bench-json", str(out)],
        capture_output=True, text=True, timeout=TIMEOUT, cwd=tmp_path, env=env)
    assert proc.returncode == 0, proc.stderr[-2000:]
    jobs = json.loads(out.read_text())["jobs"]
    whitted = [job for job in jobs if job["name"] == "viewport raytrace"
               and job["first_image_s"] is not None]
    assert whitted, jobs
    job = whitted[-1]
    assert isinstance(job["first_image_s"], float) and isinstance(job["done_s"], float)
    assert job["started_s"] <= job["first_image_s"] <= job["done_s"]
