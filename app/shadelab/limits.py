"""Resource limits: work that would not fit in memory or end in reasonable time is refused up
front, with the estimate, the limit and how to ask for more.

Each limit is a default an ordinary machine (a laptop, 2 cores, 8 GiB) runs within minutes.
``--allow-large`` (or ``SHADELAB_ALLOW_LARGE=1``, which the flag sets, so worker processes
and the viewer see it too) lifts the limits on size and time; a memory estimate beyond this
machine's physical memory is refused even then, since it would end in a MemoryError or the
OOM killer rather than an image. Pure standard library: every layer may import it.
"""

from __future__ import annotations

import os

from shadelab.errors import ShadeLabError

ALLOW_ENV = "SHADELAB_ALLOW_LARGE"
HOW = f"pass --allow-large (or set {ALLOW_ENV}=1) to run it anyway"

MAX_PIXELS = 4096 * 4096  # an image: 16.8 Mpixels
MAX_SAMPLES = 2**28  # pixels x samples per pixel of one trace (~268 M, minutes to an hour)
MAX_TRIANGLES = 4_000_000  # one scene, all objects (normals, BVH and GL buffers: ~1.5 GiB)
MAX_OBJECTS = 10_000  # one scene (each is meshed, uploaded and drawn on its own)
MAX_MESH_FILE_BYTES = 512 * 2**20  # a mesh file read whole by trimesh
MAX_VERTEX_FACES = 4096  # triangles at one vertex of a mesh file (a polygon's fan, repeated
#                          faces): smooth normals compare them pairwise, k x k
MAX_PATCHES = 20_000  # radiosity: the N x N form-factor matrix is 3.2 GB of float64


def allowed() -> bool:
    return os.environ.get(ALLOW_ENV, "") not in ("", "0")


def physical_memory() -> int:
    """Bytes of RAM of this machine (a large number where the OS does not say)."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return 2**50


def _fmt(value: float) -> str:
    for div, suffix in ((1e9, " G"), (1e6, " M"), (1e3, " k")):
        if value >= div:
            return f"{value / div:.3g}{suffix}"
    return f"{value:.3g} "


def _bytes(value: float) -> str:
    return f"{value / 2**30:.1f} GiB" if value >= 2**30 else f"{value / 2**20:.0f} MiB"


def check(what: str, estimate: float, limit: float, unit: str,
          memory_bytes: float | None = None) -> None:
    """Refuse ``estimate`` over ``limit`` (unless allowed), and any memory over the RAM."""
    if memory_bytes is not None and memory_bytes > physical_memory():
        raise ShadeLabError(f"{what}: about {_fmt(estimate)}{unit} would need "
                            f"~{_bytes(memory_bytes)} of memory, more than this machine has "
                            f"({_bytes(physical_memory())}); make it smaller")
    if estimate > limit and not allowed():
        raise ShadeLabError(f"{what}: about {_fmt(estimate)}{unit}, over the limit of "
                            f"{_fmt(limit)}{unit}; {HOW}")


def check_pixels(size: tuple[int, int], flag: str = "--size", bytes_per_pixel: int = 96) -> None:
    w, h = size
    check(f"{flag} {w}x{h}", w * h, MAX_PIXELS, "pixels", w * h * bytes_per_pixel)


def check_samples(size: tuple[int, int], spp: int, what: str = "--spp") -> None:
    w, h = size
    check(f"{what} {spp} at {w}x{h}", w * h * spp, MAX_SAMPLES, "samples")


def check_patches(count: int, key: str = "--patches") -> None:
    check(f"{key} {count}", count, MAX_PATCHES, "patches", 8.0 * count * count)
