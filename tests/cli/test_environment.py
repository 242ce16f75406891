"""A hostile environment: thread-count variables that numba and OpenMP would choke on are
dropped with one warning line, and the render goes on (issue 24, class 8)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from shadelab.environment import THREAD_VARIABLES, drop_bad_thread_counts


@pytest.mark.parametrize("value", ["0", "-3", "abc", "1.5", ""])
def test_a_bad_thread_count_is_dropped_with_one_warning(monkeypatch, capsys, value):
    monkeypatch.setenv("NUMBA_NUM_THREADS", value)
    monkeypatch.setenv("OMP_NUM_THREADS", "2")
    assert drop_bad_thread_counts() == ["NUMBA_NUM_THREADS"]
    assert "NUMBA_NUM_THREADS" not in os.environ and os.environ["OMP_NUM_THREADS"] == "2"
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"NUMBA_NUM_THREADS={value!r}" in err
    assert drop_bad_thread_counts() == []  # once


@pytest.mark.slow
def test_the_ray_tracer_runs_with_numba_threads_zero(tmp_path):
    """Before: 'ValueError: Number of threads specified must be > 0.' and a traceback."""
    env = {**os.environ, "NUMBA_NUM_THREADS": "0", "OMP_NUM_THREADS": "0"}
    out = tmp_path / "x.png"
    proc = subprocess.run([sys.executable, "-m", "shadelab", "raytrace", "cornell", "-o",
                           str(out), "--size", "8x8"], env=env, capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr and out.is_file()
    warnings = [line for line in proc.stderr.splitlines() if "warning:" in line]
    assert len(warnings) == 2 and {"NUMBA_NUM_THREADS", "OMP_NUM_THREADS"} <= \
        {w.split("=")[0].split()[-1] for w in warnings}
    assert set(THREAD_VARIABLES) >= {"NUMBA_NUM_THREADS", "OMP_NUM_THREADS"}


@pytest.mark.slow
def test_a_memory_limit_is_one_line_with_the_figure(tmp_path):
    """Under a 3 GiB address-space limit an 8192x8192 ray trace cannot allocate its image:
    one line naming the size numpy asked for, exit 2 (before: a numpy traceback)."""
    script = ("import resource, sys; resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30));"
              "from shadelab.cli import main; sys.exit(main(sys.argv[1:]))")
    proc = subprocess.run([sys.executable, "-c", script, "raytrace", "cornell", "-o",
                           str(tmp_path / "big.png"), "--size", "8192x8192", "--allow-large"],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2, proc.stderr[-2000:]
    lines = [line for line in proc.stderr.splitlines() if line.strip() and "%|" not in line]
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr[-2000:]
    assert lines[0].startswith("shadelab: error: not enough memory (Unable to allocate")
    assert "GiB" in lines[0] or "MiB" in lines[0]
    assert not list(tmp_path.iterdir())
