"""Viewer speed against Polyscope, case by case: cornell and the lecture scene, at 1280x720 and
at 1024x768 in presenter mode, each the viewer then Polyscope on the same triangles, window
size and display (alternated, so both see the same machine load); a frame's CPU time broken
into its parts; idle frames of a small and an 80k-triangle scene; and the time from process
start to the first frame on a warm cache.

The viewer runs in subprocesses (under ``xvfb-run`` when there is no display); without a
display or Xvfb the section is skipped with a note. A warm cache: one unmeasured start first,
with Python's bytecode written (``PYTHONDONTWRITEBYTECODE`` set: into ShadeLab's cache folder
by ``PYTHONPYCACHEPREFIX``), as an installed ShadeLab has it.
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

# (preset, window, presenter, overrides): the redraw cases compared with Polyscope
CASES = (("cornell", "1280x720", False, ()), ("lecture", "1280x720", False, ()),
         ("cornell", "1024x768", True, ()), ("lecture", "1024x768", True, ()))
# idle frames against scene size: the same window, cornell's 38 triangles against 81,920
MESH80K = ("sphere-shading", "1280x720", False, ("objects.0.subdivisions=6",))
FIRST_FRAME_CASE = "cornell_1280x720"   # the goal's first_frame_s
# the full bench runs every case's pair (the viewer, then Polyscope) this many times, round by
# round, and reports each case's median round: one pair's ratio moved by ±30 % on a shared VM
ROUNDS = 3
DISPLAY = "1344x800x24"                 # one Xvfb screen that holds every case's window
NOTE = ("cases: each case runs the viewer, then Polyscope, on one display, once per round (rounds: "
        "3 in the full bench, every case in turn each round); a case's figures are its median "
        "round's (by fps_over_polyscope), each round's ratios and frame times under rounds; "
        "the viewer's frames "
        "are measured once it has settled (settled_after_first_frame_s: the start-up warm-up, "
        "the job process loading the offline kernels on the other core, done; until then it "
        "draws a frame every 50 ms as an idling viewer does); frame_ms: the scene "
        "re-rendered every frame at full resolution with every panel drawn; "
        "interactive_frame_ms: the same at the drag-time render scale (0.5, what a slider or "
        "camera drag gets); idle_frame_ms: nothing changed (the cached viewport image), the GUI "
        "alone; cpu_ms: the process's CPU time per frame (llvmpipe threads included), steadier "
        "than wall time on a shared machine; breakdown: the main thread's CPU ms in each part of "
        "a frame (gui: panels built; scene: the viewport's passes; gpu_requests: renders and "
        "read-backs panels queued; readback: probe and screenshot; gui_render: the viewport's "
        "display pass into the window (ui.app.WINDOW_PASS), ImGui's GL draw and the swap) "
        "and other_cpu_ms, the rest of the frame's process CPU (the GL driver's "
        "threads: llvmpipe rasterizes there); scene_cpu_ms = redraw cpu - idle cpu; polyscope: "
        "the same triangles, window and display, every frame redrawn, vsync off; "
        "fps_over_polyscope = fps / polyscope fps (both redraw every frame), cpu_over_polyscope = "
        "polyscope's CPU ms per frame / ours; first_frame_s: "
        "from process start (imports included), after one unmeasured start (warm caches); "
        "first_frame_cpu_s: the process's CPU seconds until then (steadier under load)")


def case_name(preset: str, window: str, presenter: bool, overrides=()) -> str:
    name = "mesh80k" if overrides else preset
    return f"{name}_{window}" + ("_presenter" if presenter else "")


def viewer_command(frames: int, json_path: str, preset: str = "cornell",
                   window: str = "1280x720", presenter: bool = False,
                   overrides=()) -> list[str]:
    """The command that runs the viewer for ``frames`` frames."""
    command = [sys.executable, "-m", "shadelab", "view", preset, "--fresh", "--no-autosave",
               "--window", window, "--frames", str(frames), "--bench-json", json_path]
    for value in overrides:
        command += ["--set", value]
    return command + (["--presenter"] if presenter else [])


def polyscope_command(frames: int, json_path: str, preset: str = "cornell",
                      window: str = "1280x720", overrides=()) -> list[str] | None:
    """Polyscope on the same triangles and window (None where it is not installed)."""
    if importlib.util.find_spec("polyscope") is None:
        return None
    return [sys.executable, "-m", "shadelab.bench.polyscope_viewer", preset, window, str(frames),
            json_path, *overrides]


def on_display(commands: list[list[str]]) -> list[str] | None:
    """One command running ``commands`` in turn on the same display: the session's, or one
    Xvfb server started for all of them; None without a display and without Xvfb."""
    script = " ; ".join(shlex.join(c) for c in commands)
    if os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        return ["sh", "-c", script]
    if shutil.which("xvfb-run") is None:
        return None
    return ["xvfb-run", "-a", "-s", f"-screen 0 {DISPLAY}", "sh", "-c", script]


def warm_environment(folder: str) -> tuple[dict, str]:
    """The subprocesses' environment and where their bytecode is cached: Python's own
    ``__pycache__`` folders, or (``PYTHONDONTWRITEBYTECODE`` set) ShadeLab's cache folder."""
    # no background `shadelab warm` compiling kernels beside the measured frames (a cold
    # kernel cache is reported as kernel_cache_warm false; `shadelab warm` warms it)
    env = dict(os.environ, XDG_STATE_HOME=folder, SHADELAB_AUTOWARM="0",
               PYTHONPATH=str(Path(__file__).resolve().parents[2]))
    env.pop("PYOPENGL_PLATFORM", None)  # the viewer is GLX, never EGL
    bytecode = "__pycache__ (Python's default)"
    if env.pop("PYTHONDONTWRITEBYTECODE", None) and not env.get("PYTHONPYCACHEPREFIX"):
        from shadelab.paths import user_cache_root

        env["PYTHONPYCACHEPREFIX"] = str(user_cache_root() / "pycache")
    if env.get("PYTHONPYCACHEPREFIX"):
        bytecode = env["PYTHONPYCACHEPREFIX"]
    return env, bytecode


def _read(path: Path) -> dict | None:
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def run(quick: bool) -> dict:
    frames = 90 if quick else 200
    rounds = 1 if quick else ROUNDS
    with tempfile.TemporaryDirectory() as folder:
        env, bytecode = warm_environment(folder)
        out = Path(folder)
        commands = [viewer_command(3, str(out / "warm.json"))]  # warm caches: not measured
        peer_warm = polyscope_command(3, str(out / "warm-peer.json"))
        commands += [peer_warm] if peer_warm else []
        runs = []
        for turn in range(rounds):   # every case once per round: a load that drifts meets all
            for preset, window, presenter, overrides in (*CASES, *([MESH80K] if turn == 0
                                                                   else [])):
                name = case_name(preset, window, presenter, overrides)
                viewer_json = out / f"{name}-{turn}.json"
                peer_json = out / f"{name}-{turn}-polyscope.json"
                commands.append(viewer_command(frames, str(viewer_json), preset, window,
                                               presenter, overrides))
                peer = None if overrides else polyscope_command(frames, str(peer_json), preset,
                                                                window, overrides)
                commands += [peer] if peer else []
                runs.append((name, preset, window, presenter, overrides, viewer_json,
                             peer_json if peer else None))
        command = on_display(commands)
        if command is None:
            return {"skipped": "no DISPLAY and no xvfb-run (apt-get install xvfb)"}
        start = time.perf_counter()
        proc = subprocess.run(command, env=env, capture_output=True, text=True,
                              timeout=300 + 60 * len(commands) * frames // 90)
        wall = time.perf_counter() - start
        measured: dict[str, list[dict]] = {}
        idle = {}
        for name, preset, window, presenter, overrides, viewer_json, peer_json in runs:
            report = _read(viewer_json)
            if report is None:
                tail = (proc.stderr or proc.stdout).strip().splitlines()[-3:]
                figures = {"error": f"viewer failed (exit {proc.returncode}): "
                                    f"{' | '.join(tail)}"}
            else:
                figures = case_figures(report)
            figures.update(preset=preset, window=window, presenter=presenter)
            if overrides:
                figures["overrides"] = list(overrides)
                idle[name] = figures
                continue
            peer = None if peer_json is None else _read(peer_json)
            figures.update(peer_figures(peer, figures.get("fps"),
                                        figures.get("idle_frame_ms_median"),
                                        None if peer_json is None else ["polyscope"],
                                        figures.get("frame_cpu_ms_median")))
            measured.setdefault(name, []).append(figures)
        cases = {name: median_round(each) for name, each in measured.items()}
    if all("error" in c for c in cases.values()):
        return {"skipped": next(iter(cases.values()))["error"], "cases": cases}
    return {**summary(cases, idle, frames, wall, bytecode), "rounds": rounds}


def median_round(rounds: list[dict]) -> dict:
    """A case's figures over its rounds: the round with the median ratio to Polyscope (the
    median frame time without the peer; a failed round only if every round failed), all of
    its figures from that one pair of runs, and ``rounds``: each round's ratios and frame
    times, in the order they ran."""
    def key(figures: dict) -> float:
        ratio = figures.get("fps_over_polyscope")
        return ratio if isinstance(ratio, (int, float)) else figures.get("frame_ms_median") or 0

    good = [f for f in rounds if "error" not in f] or rounds
    chosen = sorted(good, key=key)[(len(good) - 1) // 2]
    peer = [f.get("polyscope") for f in rounds]
    summary_rows = [{"fps_over_polyscope": f.get("fps_over_polyscope"),
                     "cpu_over_polyscope": f.get("cpu_over_polyscope"),
                     "frame_ms_median": f.get("frame_ms_median"),
                     "polyscope_frame_ms_median": p.get("frame_ms_median")
                     if isinstance(p, dict) else None,
                     **({"error": f["error"]} if "error" in f else {})}
                    for f, p in zip(rounds, peer, strict=True)]
    return {**chosen, "round": rounds.index(chosen), "rounds": summary_rows}


def case_figures(report: dict) -> dict:
    """One viewer run's figures (``--bench-json``): redraw, interactive and idle frames, their
    CPU time and its breakdown, the first frame."""
    redraw = report.get("redraw_frame_ms_median")
    idle = report.get("idle_frame_ms_median")
    interactive = report.get("interactive_frame_ms_median")
    out = {"frames": report.get("frames"), "triangles": report.get("triangles"),
           "frame_ms_median": redraw, "frame_ms_max": report.get("redraw_frame_ms_max"),
           "fps": 1000.0 / redraw if redraw else None,
           "frame_cpu_ms_median": report.get("redraw_cpu_ms_median"),
           "interactive_frame_ms_median": interactive,
           "interactive_cpu_ms_median": report.get("interactive_cpu_ms_median"),
           "interactive_fps": 1000.0 / interactive if interactive else None,
           "idle_frame_ms_median": idle, "idle_cpu_ms_median": report.get("idle_cpu_ms_median"),
           "idle_fps": 1000.0 / idle if idle else None,
           "first_frame_s": report.get("first_frame_s"),
           "first_frame_cpu_s": report.get("first_frame_cpu_s"),
           # the phases began once the start-up warm-up (the job process loading the offline
           # kernels) was done: frames before it timed the warm-up's core, not the viewer
           "settled_after_first_frame_s": report.get("settled_after_first_frame_s"),
           "breakdown": {phase: report[f"{phase}_breakdown"]
                         for phase in ("redraw", "interactive", "idle")
                         if f"{phase}_breakdown" in report}}
    if report.get("redraw_cpu_ms_median") is not None and \
            report.get("idle_cpu_ms_median") is not None:
        out["scene_cpu_ms"] = report["redraw_cpu_ms_median"] - report["idle_cpu_ms_median"]
    return out


def summary(cases: dict, idle: dict, frames: int, wall: float, bytecode: str) -> dict:
    """The section: every case, the cornell 1280x720 figures at the top (the first frame's
    goal reads them), the worst case's ratio, idle CPU against scene size."""
    ratios = {name: c.get("fps_over_polyscope") for name, c in cases.items()}
    measured = [r for r in ratios.values() if isinstance(r, (int, float))]
    first = cases.get(FIRST_FRAME_CASE, {})
    out = {"frames": frames, "cases": cases,
           "fps_over_polyscope_min": min(measured) if measured else None,
           "first_frame_s": first.get("first_frame_s"),
           "first_frame_cpu_s": first.get("first_frame_cpu_s"),
           "first_frame_s_max": max((c["first_frame_s"] for c in cases.values()
                                     if c.get("first_frame_s") is not None), default=None),
           "bytecode_cache": bytecode, "kernel_cache_warm": kernel_cache_warm(),
           "process_wall_s": wall,
           "load_average": os.getloadavg()[0], "note": NOTE}
    for key in ("window", "preset", "fps", "frame_ms_median", "frame_cpu_ms_median",
                "idle_frame_ms_median", "idle_cpu_ms_median", "fps_over_polyscope"):
        out[key] = first.get(key)
    big = next(iter(idle.values()), {})
    small_cpu, big_cpu = first.get("idle_cpu_ms_median"), big.get("idle_cpu_ms_median")
    out["idle_vs_scene_size"] = {
        "cornell": {"triangles": first.get("triangles"), "idle_cpu_ms": small_cpu,
                    "idle_frame_ms": first.get("idle_frame_ms_median")},
        "mesh80k": {"triangles": big.get("triangles"), "idle_cpu_ms": big_cpu,
                    "idle_frame_ms": big.get("idle_frame_ms_median"),
                    "redraw_cpu_ms": big.get("frame_cpu_ms_median"),
                    **({"error": big["error"]} if "error" in big else {})},
        "idle_cpu_mesh80k_over_cornell": (big_cpu / small_cpu
                                          if small_cpu and big_cpu else None)}
    return out


def kernel_cache_warm() -> bool | None:
    """Whether ``shadelab warm`` has filled the numba kernel cache (None: no cache folder)."""
    from shadelab.cli.warm import done_mark

    mark = done_mark()
    return None if mark is None else mark.exists()


def peer_figures(polyscope: dict | None, fps: float | None, idle_ms: float | None,
                 command: list[str] | None, cpu_ms: float | None = None) -> dict:
    """Polyscope's figures beside the viewer's, or why there are none; ``cpu_over_polyscope``:
    Polyscope's CPU ms per redrawn frame over ours (the same comparison in CPU time, which a
    shared machine's load disturbs less than wall time)."""
    if command is None:
        from shadelab.bench.goals import INSTALL_PEERS

        return {"polyscope": f"not installed ({INSTALL_PEERS})"}
    if polyscope is None:
        return {"polyscope": "failed (no report written)"}
    peer_fps = 1000.0 / polyscope["frame_ms_median"]
    peer_cpu = polyscope.get("cpu_ms_median")
    return {"polyscope": {**polyscope, "fps": peer_fps},
            "fps_over_polyscope": fps / peer_fps if fps else None,
            "cpu_over_polyscope": peer_cpu / cpu_ms if peer_cpu and cpu_ms else None,
            "idle_fps_over_polyscope": 1000.0 / idle_ms / peer_fps if idle_ms else None}


if __name__ == "__main__":
    print(json.dumps(run("--quick" in sys.argv), indent=2))
