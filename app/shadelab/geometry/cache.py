"""An on-disk cache of derived mesh arrays (pure: numpy only), so a viewer that opens a preset
it has seen before builds its meshes without importing trimesh (and scipy, networkx) at all:
about a second of the first frame on this project's 2-core machine.

What is cached is what trimesh computes from the scene's own numbers: the primitives' vertices
and faces (an icosphere, a box, ...) and, per caster, the merged closed mesh and its face
adjacency for the shadow-volume silhouettes. Entries are keyed by a BLAKE2 hash of their inputs
and the trimesh version, written atomically (a temporary name, then a rename) and read with
``allow_pickle=False``; an unreadable or mismatched entry is ignored and rebuilt, never an
error. ``SHADELAB_CACHE_DIR`` moves the folder (default ``$XDG_CACHE_HOME/shadelab`` or
``~/.cache/shadelab``); ``SHADELAB_CACHE_DIR=off`` turns the cache off.
"""

from __future__ import annotations

import hashlib
import os
import stat
import tempfile
from functools import lru_cache
from pathlib import Path

import numpy as np

CACHE_ENV = "SHADELAB_CACHE_DIR"
FORMAT = 1          # bump when what an entry holds changes


def cache_root() -> Path | None:
    """ShadeLab's cache folder (meshes, the benches' references), or None when turned off."""
    chosen = os.environ.get(CACHE_ENV, "")
    if chosen.strip().lower() == "off":
        return None
    if chosen:
        return Path(chosen)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "shadelab"


def cache_dir() -> Path | None:
    """The folder of the mesh cache, or None when it is turned off."""
    root = cache_root()
    return None if root is None else root / "meshes"


@lru_cache(maxsize=1)
def _trimesh_version() -> str:
    from shadelab.distributions import dist_version  # not importlib.metadata: a slow import

    return dist_version("trimesh") or "unknown"


def key(kind: str, *parts) -> str:
    """A file-name-safe key of ``parts`` (numbers, strings, tuples, numpy arrays)."""
    h = hashlib.blake2b(digest_size=20)
    h.update(f"{kind}|{FORMAT}|{_trimesh_version()}".encode())
    for part in parts:
        if isinstance(part, np.ndarray):
            h.update(f"|{part.dtype}{part.shape}|".encode())
            h.update(np.ascontiguousarray(part).tobytes())
        else:
            h.update(f"|{part!r}".encode())
    return f"{kind}-{h.hexdigest()}"


def load(name: str) -> dict[str, np.ndarray] | None:
    """The arrays stored under ``name``, or None (not there, unreadable, cache off)."""
    folder = cache_dir()
    if folder is None:
        return None
    path = folder / f"{name}.npz"
    try:
        # Opened without blocking and read only if it is a regular file: an entry that is a
        # FIFO (or a device) would hang np.load's open; it is a miss, rebuilt by store()
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(fd, "rb") as handle:
            if not stat.S_ISREG(os.fstat(handle.fileno()).st_mode):
                return None
            with np.load(handle, allow_pickle=False) as data:
                return {k: data[k] for k in data.files}
    except (OSError, ValueError, EOFError, KeyError):  # missing, damaged, not an npz
        return None
    except Exception:  # noqa: BLE001 - zipfile.BadZipFile and kin: a cache miss, not an error
        return None


def store(name: str, arrays: dict[str, np.ndarray]) -> None:
    """Write ``arrays`` under ``name`` (atomically; a full or read-only disk is ignored)."""
    folder = cache_dir()
    if folder is None:
        return
    try:
        folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{name}.", suffix=".tmp")
        try:
            with os.fdopen(fd, "wb") as f:
                np.savez(f, **arrays)
            os.replace(tmp, folder / f"{name}.npz")
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
    except OSError:
        return
