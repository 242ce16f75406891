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


WALK = '''name = "walk"

[[steps]]
title = "Phong"
caption = "I = Ia ka Od"
preset = "cornell"

[[steps]]
title = "Ray tracing"
caption = "I = ... + ks Ir + kt It"
preset = "cornell"
set = ["raytrace.depth=1"]
pipeline = "raytrace"

[[steps]]
title = "Radiosity"
caption = "B_i = E_i + rho_i sum_j B_j F_i-j"
preset = "cornell"
set = ["radiosity.patches=40", "radiosity.form_factors=raycast"]
pipeline = "radiosity"
'''


@pytest.mark.skipif(shutil.which("xvfb-run") is None, reason="needs xvfb-run")
def test_the_bench_walks_the_lesson_without_a_restart_and_times_each_page_down(tmp_path):
    """``--bench-page-down 2``: two PageDowns in one process, each once the step (and the
    next step's prefetch) settled; each step's job is recorded after its own PageDown."""
    lesson = tmp_path / "walk.toml"
    lesson.write_text(WALK, encoding="utf-8")
    out = tmp_path / "bench.json"
    env = dict(os.environ, PYTHONPATH=str(ROOT / "app"))
    proc = subprocess.run(
        ["xvfb-run", "-a", sys.executable, "-m", "shadelab", "view",
         "--lesson", str(lesson), "--step", "1", "--frames", "5", "--bench-page-down", "2",
         "--window", "480x360", "--no-autosave", "--bench-json", str(out)],
        capture_output=True, text=True, timeout=TIMEOUT, cwd=tmp_path, env=env)
    assert proc.returncode == 0, proc.stderr[-2000:]
    report = json.loads(out.read_text())
    presses = report["page_downs_s"]
    assert len(presses) == 2 and presses[0] < presses[1]
    assert report["page_down_s"] == presses[0]
    jobs = {job["name"]: job for job in report["jobs"] if job["name"].startswith("viewport")}
    whitted, radiosity = jobs["viewport raytrace"], jobs["viewport radiosity"]
    assert presses[0] <= whitted["started_s"] < presses[1]
    assert presses[1] <= radiosity["started_s"]
    for job in (whitted, radiosity):
        assert job["first_image_s"] is not None and job["done_s"] is not None
