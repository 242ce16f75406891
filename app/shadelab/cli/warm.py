"""``shadelab warm``: compile the ray tracer's, path tracer's and radiosity's numba kernels
into numba's on-disk cache, so the first offline image in front of a class waits for no JIT,
and fill the mesh cache (:mod:`shadelab.geometry.cache`) with the shipped presets' meshes and
shadow-volume silhouettes, so the viewer's first frame imports no trimesh.

``make install`` runs it once after installing; the viewer also warms the kernels of the
pipeline it starts in. Running it again only loads the cache (a fraction of a second).
"""

from __future__ import annotations

import argparse
import sys
import time


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("warm", help="compile the CPU renderers' kernels ahead of time")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from shadelab.lab.pipeline_jobs import warm_kernels

    start = time.perf_counter()
    count = warm_meshes()
    print(f"warm: {count} preset meshes cached ({time.perf_counter() - start:.1f} s)",
          file=sys.stderr, flush=True)
    for step in warm_kernels(None, None):
        seconds = next(iter(step.stats.values()))
        print(f"warm: {step.message} ({seconds:.1f} s)", file=sys.stderr, flush=True)
    print(f"warm: kernels ready in {time.perf_counter() - start:.1f} s", file=sys.stderr)
    return 0


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
