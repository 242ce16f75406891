"""``shadelab warm``: compile the ray tracer's, path tracer's and radiosity's numba kernels
into numba's on-disk cache, so the first offline image in front of a class waits for no JIT,
and fill the mesh cache (:mod:`shadelab.geometry.cache`) with the shipped presets' meshes and
shadow-volume silhouettes, so the viewer's first frame imports no trimesh.

``make install`` runs it once after installing; the viewer also warms the kernels of the
pipeline it starts in. Running it again only loads the cache (a fraction of a second).

A pip install has no ``make install``: the first use of the command line (the viewer
included) whose kernel cache folder holds no mark of a finished warm-up for this ShadeLab,
numba and Python starts ``shadelab warm --quiet`` in the background, detached, and says so
in one line (:func:`autowarm`). Numba's cache is keyed by the CPU and the source files'
timestamps, so a cache shipped in the wheel would be rejected on many machines; compiling
once on the user's own machine is the reliable way. ``SHADELAB_AUTOWARM=0`` turns it off.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

AUTOWARM_ENV = "SHADELAB_AUTOWARM"
RETRY_S = 15 * 60      # a warm-up started this recently (maybe still running) is not restarted


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("warm", help="compile the CPU renderers' kernels ahead of time")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from shadelab.lab.pipeline_jobs import warm_kernels
    from shadelab.progress import QUIET

    def say(line: str) -> None:
        if not QUIET:
            print(f"warm: {line}", file=sys.stderr, flush=True)

    start = time.perf_counter()
    count = warm_meshes()
    say(f"{count} preset meshes cached ({time.perf_counter() - start:.1f} s)")
    for scene in _warm_scenes():
        for step in warm_kernels(scene, None):
            seconds = next(iter(step.stats.values()))
            say(f"{step.message} ({seconds:.1f} s)")
    say(f"kernels ready in {time.perf_counter() - start:.1f} s "
        f"(cache: {os.environ.get('NUMBA_CACHE_DIR', 'numba default')})")
    mark = done_mark()
    if mark is not None:
        try:
            mark.parent.mkdir(parents=True, exist_ok=True)
            mark.write_text(f"{time.time():.0f}\n")
        except OSError:  # an unwritable cache: the kernels were still compiled for this run
            pass
    return 0


#: Presets whose scenes the kernels are compiled on besides cornell's: their scenes make numba
#: compile further specializations of some kernels (seen: add_misses and hit_surfaces on
#: lecture), which a user's first render would otherwise wait for.
WARM_PRESETS = ("lecture", "whitted")


def _warm_scenes():
    from shadelab.errors import ShadeLabError
    from shadelab.scene.preset import load_preset

    yield None                     # cornell (warm_kernels' own choice)
    for name in WARM_PRESETS:
        try:
            yield load_preset(name)
        except ShadeLabError:      # a renamed preset must not break the warm-up
            continue


def _stamp() -> str:
    from shadelab.distributions import dist_version  # not importlib.metadata: a slow import
    from shadelab.version import __version__

    numba = dist_version("numba") or "unknown"
    return f"{__version__}-numba{numba}-py{sys.version_info[0]}{sys.version_info[1]}"


def done_mark() -> Path | None:
    """The file a finished ``shadelab warm`` leaves in the kernel cache folder."""
    folder = os.environ.get("NUMBA_CACHE_DIR")
    return Path(folder) / f"warm-{_stamp()}.done" if folder else None


def autowarm(command: str | None) -> bool:
    """On the first use of the CLI with a cold kernel cache, start ``shadelab warm`` in the
    background (detached: it outlives a short command) and say so in one line. True when it
    was started. Not for ``warm`` itself, nor with ``SHADELAB_AUTOWARM=0``."""
    if command == "warm" or os.environ.get(AUTOWARM_ENV, "1").strip() == "0":
        return False
    mark = done_mark()
    if mark is None or mark.exists():
        return False
    started = mark.with_suffix(".started")
    try:
        if time.time() - started.stat().st_mtime < RETRY_S:
            return False
    except OSError:
        pass
    try:
        started.parent.mkdir(parents=True, exist_ok=True)
        started.write_text(f"{os.getpid()}\n")
        subprocess.Popen([sys.executable, "-m", "shadelab", "warm", "--quiet"],
                         stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                         stderr=subprocess.DEVNULL, start_new_session=True,
                         close_fds=True)
    except OSError:  # an unwritable cache folder (its note is printed) or no fork: skip
        return False
    from shadelab.progress import note

    note(f"first run: compiling the CPU renderers' kernels once, in the background "
         f"(20-60 s; cached in '{mark.parent}')")
    return True


def warm_meshes() -> int:
    """Build every shipped preset's meshes and its casters' closed meshes once (cached)."""
    from shadelab.errors import ShadeLabError
    from shadelab.geometry.mesh import scene_meshes
    from shadelab.geometry.silhouette import closed_caster
    from shadelab.scene.preset import list_presets, load_preset

    count = 0
    for name in list_presets():
        try:
            scene = load_preset(name)
            meshes = scene_meshes(scene)
        except ShadeLabError:      # the fail-* presets that are meant to be refused
            continue
        for mesh in meshes:
            if scene.objects[mesh.index].cast_shadows:
                closed_caster(mesh.vertices, mesh.faces)
            count += 1
    return count
