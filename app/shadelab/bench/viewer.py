"""Viewer speed: frame time with the GUI drawn (1280x720, cornell, one light) and the time
from process start to the first frame. The viewer runs in a subprocess (under ``xvfb-run``
when there is no display); without a display or Xvfb the section is skipped with a note.
"""

from __future__ import annotations

import importlib.util
import json
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

WINDOW = "1280x720"
NOTE = ("frame_ms: the scene re-rendered every frame at full resolution with every panel drawn; "
        "interactive_frame_ms: the same at the drag-time render scale (0.5, what a slider or "
        "camera drag gets); idle_frame_ms: nothing changed, the GUI alone; first frame counted "
        "from process start (imports included); cpu_ms: this process's CPU time per frame "
        "(llvmpipe threads included), steadier than wall time on a shared machine; polyscope: the "
        "same cornell triangles, window and display, every frame redrawn, vsync off; "
        "fps_over_polyscope = fps / polyscope fps (both redraw every frame), "
        "idle_fps_over_polyscope = idle_fps / polyscope fps (the cached viewport image)")


def viewer_command(frames: int, json_path: str) -> list[str]:
    """The command that runs the viewer for ``frames`` frames."""
    return [sys.executable, "-m", "shadelab", "view", "cornell", "--fresh", "--no-autosave",
            "--window", WINDOW, "--frames", str(frames), "--bench-json", json_path]


def polyscope_command(frames: int, json_path: str) -> list[str] | None:
    """Polyscope on the same triangles and window (None where it is not installed)."""
    if importlib.util.find_spec("polyscope") is None:
        return None
    return [sys.executable, "-m", "shadelab.bench.polyscope_viewer", "cornell", WINDOW, str(frames),
            json_path]


def on_display(commands: list[list[str]]) -> list[str] | None:
    """One command running ``commands`` in turn on the same display: the session's, or one
    Xvfb server started for all of them; None without a display and without Xvfb."""
    script = " ; ".join(shlex.join(c) for c in commands)
    if os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        return ["sh", "-c", script]
    if shutil.which("xvfb-run") is None:
        return None
    return ["xvfb-run", "-a", "-s", "-screen 0 1344x784x24", "sh", "-c", script]


def run(quick: bool) -> dict:
    frames = 90 if quick else 300
    with tempfile.TemporaryDirectory() as folder:
        json_path = str(Path(folder) / "viewer.json")
        peer_path = str(Path(folder) / "polyscope.json")
        peer = polyscope_command(frames, peer_path)
        command = on_display([viewer_command(frames, json_path)] + ([peer] if peer else []))
        if command is None:
            return {"skipped": "no DISPLAY and no xvfb-run (apt-get install xvfb)"}
        env = dict(os.environ, XDG_STATE_HOME=folder,
                   PYTHONPATH=str(Path(__file__).resolve().parents[2]))
        env.pop("PYOPENGL_PLATFORM", None)  # the viewer is GLX, never EGL
        start = time.perf_counter()
        proc = subprocess.run(command, env=env, capture_output=True, text=True, timeout=600)
        wall = time.perf_counter() - start
        if not Path(json_path).is_file():
            tail = (proc.stderr or proc.stdout).strip().splitlines()[-3:]
            return {"skipped": f"viewer failed (exit {proc.returncode}): {' | '.join(tail)}"}
        report = json.loads(Path(json_path).read_text(encoding="utf-8"))
        polyscope = (json.loads(Path(peer_path).read_text(encoding="utf-8"))
                     if Path(peer_path).is_file() else None)
    redraw = report.get("redraw_frame_ms_median")
    idle = report.get("idle_frame_ms_median")
    fps = 1000.0 / redraw if redraw else None
    return {"window": WINDOW, "preset": "cornell", "lights": 1, "frames": report["frames"],
            "frame_ms_median": redraw, "frame_ms_max": report.get("redraw_frame_ms_max"),
            "fps": fps, "frame_cpu_ms_median": report.get("redraw_cpu_ms_median"),
            "interactive_frame_ms_median": report.get("interactive_frame_ms_median"),
            "interactive_cpu_ms_median": report.get("interactive_cpu_ms_median"),
            "interactive_fps": (1000.0 / report["interactive_frame_ms_median"]
                                if report.get("interactive_frame_ms_median") else None),
            "idle_frame_ms_median": idle,
            "idle_cpu_ms_median": report.get("idle_cpu_ms_median"),
            "idle_fps": 1000.0 / idle if idle else None,
            "first_frame_s": report["first_frame_s"], "process_wall_s": wall,
            "note": NOTE, "load_average": os.getloadavg()[0], **peer_figures(polyscope, fps,
                                                                              idle, peer)}


def peer_figures(polyscope: dict | None, fps: float | None, idle_ms: float | None,
                 command: list[str] | None) -> dict:
    """Polyscope's figures beside the viewer's, or why there are none."""
    if command is None:
        from shadelab.bench.goals import INSTALL_PEERS

        return {"polyscope": f"not installed ({INSTALL_PEERS})"}
    if polyscope is None:
        return {"polyscope": "failed (no report written)"}
    peer_fps = 1000.0 / polyscope["frame_ms_median"]
    return {"polyscope": {**polyscope, "fps": peer_fps},
            "fps_over_polyscope": fps / peer_fps if fps else None,
            "idle_fps_over_polyscope": 1000.0 / idle_ms / peer_fps if idle_ms else None}

if __name__ == "__main__":
    print(json.dumps(run("--quick" in sys.argv), indent=2))
