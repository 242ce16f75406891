"""Progress in real units (issue 20, item 5): offline bars count rays, samples and patches
(not per-mille), are drawn only when stderr is a terminal (never into a pipe or a log), and
the CLI's global --quiet prints nothing on stderr on success."""

from __future__ import annotations

import fcntl
import io
import os
import pty
import struct
import subprocess
import sys
import termios
import threading

import pytest
from tqdm import tqdm

from shadelab import progress
from shadelab.progress import Progress


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def _job(stats_per_step):
    n = len(stats_per_step)
    for i, stats in enumerate(stats_per_step, 1):
        yield Progress(None, i / n, f"step {i}/{n}", stats)


@pytest.fixture
def recorded_bars(monkeypatch):
    """progress.bar replaced by a real tqdm that always draws into a buffer, kept for checks."""
    bars = []

    def bar(total, desc, unit, show=True, **kwargs):
        made = tqdm(total=total, desc=desc, unit=unit, file=io.StringIO(), mininterval=0)
        bars.append(made)
        return made

    monkeypatch.setattr(progress, "bar", bar)
    return bars


def test_raytrace_counts_every_ray_cast(recorded_bars):
    steps = [{"rays": 1000}, {"rays": 2600}, {"rays": 4000}]
    progress.run_to_end(_job(steps), desc="raytrace")
    (bar,) = recorded_bars
    assert bar.unit == "rays" and bar.n == 4000 and bar.total == 4000


def test_pathtrace_counts_samples_and_projects_the_total(recorded_bars):
    seen = []
    original = progress.Progress

    def job():
        for i in range(1, 5):  # 4 tiles of 8x2 pixels at 2 spp: 32 samples each
            step = original(None, i / 4, "", {"samples": 32 * i})
            yield step
            seen.append(recorded_bars[0].total)

    progress.run_to_end(job(), desc="pathtrace")
    bar = recorded_bars[0]
    assert bar.unit == "samples" and bar.n == 128 and bar.total == 128
    assert seen == [128, 128, 128, 128]          # the projection is exact from the first tile


def test_radiosity_counts_patches(recorded_bars):
    steps = [{"target_patches": 400}] * 3 + [{"target_patches": 400, "patches": 402}]
    progress.run_to_end(_job(steps), desc="radiosity")
    bar = recorded_bars[0]
    assert bar.unit == "patches" and bar.total == 400 and bar.n == 400


def test_a_terminal_gets_a_bar_named_in_its_unit(monkeypatch):
    term = _Terminal()
    monkeypatch.setattr(sys, "stderr", term)
    monkeypatch.setattr(progress, "QUIET", False)
    progress.run_to_end(_job([{"samples": 64}, {"samples": 128}]), desc="pathtrace")
    out = term.getvalue()
    assert "pathtrace" in out and "samples/s" in out and "‰" not in out


def test_a_pipe_gets_no_bar_and_quiet_silences_a_terminal(monkeypatch):
    pipe = io.StringIO()
    monkeypatch.setattr(sys, "stderr", pipe)
    progress.run_to_end(_job([{"rays": 10}, {"rays": 20}]), desc="raytrace")
    assert pipe.getvalue() == ""
    term = _Terminal()
    monkeypatch.setattr(sys, "stderr", term)
    monkeypatch.setattr(progress, "QUIET", True)
    progress.run_to_end(_job([{"rays": 10}, {"rays": 20}]), desc="raytrace")
    progress.note("something to say")
    assert term.getvalue() == ""


def _cli(args, tmp_path, stderr=subprocess.PIPE):
    env = dict(os.environ)
    return subprocess.run([sys.executable, "-m", "shadelab", *args], cwd=tmp_path, env=env,
                          stdout=subprocess.PIPE, stderr=stderr, text=True, timeout=600)


@pytest.mark.slow
def test_cli_into_a_pipe_has_no_bar_and_quiet_nothing_on_stderr(tmp_path):
    run = _cli(["raytrace", "lecture", "-o", "a.png", "--size", "24x16"], tmp_path)
    assert run.returncode == 0, run.stderr
    assert "\r" not in run.stderr and "rays/s" not in run.stderr
    for args in (["--quiet", "raytrace", "lecture", "-o", "b.png", "--size", "24x16"],
                 ["pathtrace", "lecture", "-o", "c.png", "--size", "8x8", "--spp", "2", "-q"],
                 ["raytrace", "--set", "camera.eye=0,-50,0", "--set", "camera.target=0,-60,0",
                  "lecture", "-o", "d.png", "--size", "8x8", "--quiet"]):
        run = _cli(args, tmp_path)
        assert run.returncode == 0 and run.stderr == "", (args, run.stderr)
        assert run.stdout.startswith("wrote ")
    loud = _cli(["raytrace", "--set", "camera.eye=0,-50,0", "--set", "camera.target=0,-60,0",
                 "lecture", "-o", "e.png", "--size", "8x8"], tmp_path)
    assert loud.stderr.startswith("note: no object is visible")   # what --quiet silenced


@pytest.mark.slow
def test_cli_on_a_terminal_shows_the_bar_in_rays(tmp_path):
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 40, 120, 0, 0))  # 120 columns
    chunks = []

    def read():
        while True:
            try:
                data = os.read(master, 4096)
            except OSError:
                return
            if not data:
                return
            chunks.append(data)

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    try:
        run = _cli(["raytrace", "lecture", "-o", "a.png", "--size", "64x48"], tmp_path,
                   stderr=slave)
    finally:
        os.close(slave)
        reader.join(timeout=10)
        os.close(master)
    text = b"".join(chunks).decode(errors="replace")
    assert run.returncode == 0
    assert "raytrace" in text and "rays" in text and "‰" not in text
