"""An installed package's version without ``importlib.metadata``: importing that module costs
~50-150 ms of a start on two cores (email parsing, zip files, CSV), and the viewer's first
frame needed it only for cache keys (the mesh cache's trimesh version, the kernel cache's numba
version). Pure standard library.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path


def dist_version(name: str) -> str | None:
    """``name``'s version from its ``NAME-VERSION.dist-info`` folder beside the package (what
    ``importlib.metadata.version`` returns for an installed wheel); ``importlib.metadata``
    where there is no such folder (an egg, an odd layout); None when it is not installed."""
    try:
        spec = importlib.util.find_spec(name)
    except (ImportError, ValueError):
        spec = None
    if spec is None:
        return None
    places = [Path(p).parent for p in (spec.submodule_search_locations or [])]
    if spec.origin and not places:
        places = [Path(spec.origin).parent]
    for site in places:
        found = sorted(site.glob(f"{name}-*.dist-info"))
        if len(found) == 1:
            return found[0].name[len(name) + 1:-len(".dist-info")]
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(name)
    except PackageNotFoundError:
        return None
