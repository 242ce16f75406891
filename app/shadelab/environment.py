"""The process environment ShadeLab's numerics read, checked before they read it.

numba and the OpenMP / BLAS runtimes read thread counts from the environment when they first
start: ``NUMBA_NUM_THREADS=0`` ends the first kernel call in numba's ValueError traceback. A
value that is not a positive whole number is dropped here, before any of them is imported,
with one warning line naming it; the runtime then uses its default (one per core). Pure
standard library.
"""

from __future__ import annotations

import os
import sys

THREAD_VARIABLES = ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS",
                    "MKL_NUM_THREADS")


def _positive_int(text: str) -> bool:
    try:
        return int(text.strip()) >= 1
    except ValueError:
        return False


def drop_bad_thread_counts(stream=None) -> list[str]:
    """Remove thread-count variables that are not positive integers; warn once per name on
    ``stream`` (stderr by default). Returns the names dropped."""
    dropped = []
    for name in THREAD_VARIABLES:
        value = os.environ.get(name)
        if value is None or _positive_int(value):
            continue
        del os.environ[name]
        dropped.append(name)
        print(f"shadelab: warning: {name}={value!r} is not a positive thread count; ignored "
              "(the default, one thread per core, is used)", file=stream or sys.stderr)
    return dropped
