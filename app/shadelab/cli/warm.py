"""``shadelab warm``: compile the ray tracer's, path tracer's and radiosity's numba kernels
into numba's on-disk cache, so the first offline image in front of a class waits for no JIT.

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
    from shadelab.ui.pipeline_jobs import warm_kernels

    start = time.perf_counter()
    for step in warm_kernels(None, None):
        seconds = next(iter(step.stats.values()))
        print(f"warm: {step.message} ({seconds:.1f} s)", file=sys.stderr, flush=True)
    print(f"warm: kernels ready in {time.perf_counter() - start:.1f} s", file=sys.stderr)
    return 0
