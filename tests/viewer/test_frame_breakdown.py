"""End to end: ``shadelab view --frames N --bench-json F`` (the bench's viewer run) reports a
frame's CPU time broken into its parts; each part is non-negative, the parts sum to no more
than the frame's CPU time, idle frames have no scene pass and redrawn ones have one; the
viewer never imports OpenGL.GL. Figures only: no speed is asserted."""

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
def test_bench_run_breaks_each_frame_into_parts_within_its_cpu_time(tmp_path):
    from shadelab.lab.recorder import PARTS

    out = tmp_path / "bench.json"
    env = dict(os.environ, PYTHONPATH=str(ROOT / "app"), SHADELAB_AUTOWARM="0",
               XDG_STATE_HOME=str(tmp_path))
    env.pop("PYOPENGL_PLATFORM", None)
    code = ("import sys, runpy\n"
            "sys.argv = ['shadelab', 'view', 'lecture', '--fresh', '--no-autosave', '--window',"
            " '800x600', '--frames', '45', '--bench-json', sys.argv[1]]\n"
            "try:\n"
            "    runpy.run_module('shadelab', run_name='__main__')\n"
            "finally:\n"
            "    print('OpenGL.GL' in sys.modules)\n")
    proc = subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1024x768x24", sys.executable,
                           "-c", code, str(out)], capture_output=True, text=True,
                          timeout=TIMEOUT, cwd=tmp_path, env=env)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.strip().splitlines()[-1] == "False"
    report = json.loads(out.read_text())
    assert report["triangles"] > 15000 and report["first_frame_cpu_s"] > 0.0
    for phase in ("idle", "redraw", "interactive"):
        parts = report[f"{phase}_breakdown"]
        assert set(parts["cpu_ms"]) == set(PARTS)
        assert all(v >= 0.0 for v in parts["cpu_ms"].values()), parts
        assert all(v >= 0.0 for v in parts["wall_ms"].values()), parts
        assert parts["other_cpu_ms"] >= 0.0
        # medians of parts against the median frame: within 5 % (each frame's own sum is
        # at most its CPU time: parts_over_frame_cpu_max)
        assert sum(parts["cpu_ms"].values()) <= parts["frame_cpu_ms"] * 1.05 + 0.5, parts
        assert sum(parts["wall_ms"].values()) <= parts["frame_wall_ms"] * 1.05 + 0.5, parts
        assert parts["parts_over_frame_cpu_max"] <= 1.0 + 1e-6, parts
        assert parts["cpu_ms"]["gui"] > 0.0 and parts["cpu_ms"]["gui_render"] > 0.0
    assert report["idle_breakdown"]["cpu_ms"]["scene"] == 0.0   # the cached image
    assert report["redraw_breakdown"]["cpu_ms"]["scene"] > 0.0
