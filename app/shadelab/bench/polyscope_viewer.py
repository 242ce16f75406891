"""The bench's peer: Polyscope drawing the same triangles in the same window size.

Run as ``python -m shadelab.bench.polyscope_viewer PRESET WxH FRAMES OUT.json [KEY=VALUE...]``
(the preset's ``--set`` overrides; by
:mod:`shadelab.bench.viewer`, on the display the viewer used). Every frame is redrawn
(``set_always_redraw``), vsync off and no frame cap, so the figure is Polyscope's full
redraw rate; ``first_frame_s`` counts from process start, imports included, as the viewer's.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

WARMUP = 10  # frames left out of the median (shader compiles, first uploads)


def since_process_start() -> float | None:
    """Seconds since this process started (Linux /proc), or None elsewhere."""
    import os

    try:
        ticks = os.sysconf("SC_CLK_TCK")
        start = int(Path("/proc/self/stat").read_text().rsplit(")", 1)[1].split()[19]) / ticks
        return float(Path("/proc/uptime").read_text().split()[0]) - start
    except (OSError, ValueError, IndexError):
        return None


def _version() -> str | None:
    from importlib import metadata

    try:
        return metadata.version("polyscope")
    except metadata.PackageNotFoundError:
        return None


def main(argv: list[str]) -> int:
    preset, window, frames, out, overrides = argv[0], argv[1], int(argv[2]), argv[3], argv[4:]
    import numpy as np
    import polyscope as ps

    from shadelab.geometry.mesh import scene_meshes
    from shadelab.scene.preset import load_preset

    meshes = scene_meshes(load_preset(preset, overrides))
    width, height = (int(v) for v in window.split("x"))
    ps.set_program_name("shadelab bench: polyscope")
    ps.set_window_size(width, height)
    ps.set_enable_vsync(False)
    ps.set_max_fps(-1)
    ps.set_always_redraw(True)
    ps.init()
    for mesh in meshes:
        ps.register_surface_mesh(f"object{mesh.index}", mesh.vertices, mesh.faces)
    times, cpu = [], []
    first = None
    for _ in range(frames):
        ps.frame_tick()
        times.append(time.perf_counter())
        cpu.append(time.process_time())
        if first is None:
            first = since_process_start()
    ms = np.diff(np.asarray(times))[WARMUP:] * 1000.0
    cpu_ms = np.diff(np.asarray(cpu))[WARMUP:] * 1000.0
    report = {"frames": frames, "window": window, "triangles": int(sum(len(m.faces)
                                                                       for m in meshes)),
              "frame_ms_median": float(np.median(ms)), "cpu_ms_median": float(np.median(cpu_ms)),
              "first_frame_s": first, "version": _version()}
    Path(out).write_text(json.dumps(report), encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
