"""The contract between offline renderers (ray tracing, path tracing, radiosity) and their
consumers (the CLI's tqdm bar, the viewer's side panel, benchmarks).

An offline render is a generator that yields :class:`Progress` after each pass, tile or
iteration. Bars count real units (rays, samples, patches) and are drawn only where a person
watches: stderr a terminal, or a Jupyter cell (``tqdm.auto``); never into logs or pipes.
The consumer cancels by closing the generator (``gen.close()``) or simply by not asking for
more; the renderer must stop promptly between chunks (keep chunks well under 0.2 s
so the viewer's Cancel button feels immediate). Pure module: no GL, no GUI.
"""

from __future__ import annotations

import sys
import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Iterator

import numpy as np


@dataclass
class Progress:
    """One step of an offline render.

    Attributes
    ----------
    image : (H, W, 3) float32 linear radiance so far (row 0 at the top), or None
    fraction : float in [0, 1], how much of the job is done
    message : short status line for the progress bar ("pass 3/16", "iteration 40")
    stats : figures to report at the end (rays/s, depth reached, residual, patch count, ...)
    """

    image: np.ndarray | None
    fraction: float
    message: str = ""
    stats: dict = field(default_factory=dict)


#: How each offline job counts its work, by the ``desc`` it runs under: (unit, the key of
#: :attr:`Progress.stats` holding the running count). Ray tracing counts every ray cast
#: (primary, secondary and shadow: the rate is the Mrays/s reported at the end), path
#: tracing the pixel samples, radiosity the patches (the target count times the fraction
#: done: form-factor rows, then the solver's sweeps over them).
UNITS = {"raytrace": ("rays", "rays"), "pathtrace": ("samples", "samples"),
         "radiosity": ("patches", None)}

QUIET = False           # the CLI's --quiet: no bar, no busy line, no note on stderr


def in_notebook() -> bool:
    """True inside a Jupyter kernel (tqdm.auto then draws its notebook bar)."""
    ipython = sys.modules.get("IPython")
    if ipython is None:
        return False
    try:
        shell = ipython.get_ipython()
        return shell is not None and "IPKernelApp" in shell.config
    except Exception:  # an unusual shell: no notebook bar
        return False


def interactive(stream=None) -> bool:
    """Whether a bar may be drawn: a person watches ``stream`` (stderr by default: a
    terminal, or a notebook's cell) and --quiet is off. Logs, pipes and CI get no bar."""
    if QUIET:
        return False
    stream = sys.stderr if stream is None else stream
    try:
        if stream.isatty():
            return True
    except (AttributeError, ValueError):  # a closed or unusual stream
        pass
    return in_notebook()


def note(message: str) -> None:
    """One line for the user on stderr (``note: ...``), silenced by --quiet."""
    if not QUIET:
        print(f"note: {message}", file=sys.stderr, flush=True)


def bar(total: int | None, desc: str, unit: str, show: bool = True, **kwargs):
    """A tqdm bar counting ``unit`` (tqdm.auto: a widget in Jupyter), drawn only when
    :func:`interactive`; otherwise a disabled bar that writes nothing."""
    from tqdm.auto import tqdm

    return tqdm(total=total, desc=desc, unit=unit, unit_scale=True, leave=False,
                disable=not (show and interactive()), dynamic_ncols=True, **kwargs)


def run_to_end(jobs: Iterator[Progress], desc: str = "", show: bool = True,
               unit: tuple[str, str | None] | None = None) -> Progress:
    """Drive a progressive job to completion; return the last Progress.

    The bar (on a terminal or in a notebook only, see :func:`interactive`) counts real work:
    ``unit`` = (name, stats key) or the entry of :data:`UNITS` for ``desc``: the count is
    ``step.stats[key]`` and the total is projected from it and ``step.fraction``; with no key
    the total is ``stats["target_patches"]`` (or ``stats["patches"]``) and the count that
    times the fraction. Unknown jobs count per cent.
    """
    name, key = unit or UNITS.get(desc, ("%", None))
    last = None
    with bar(None, desc, name, show) as progress_bar:
        for step in jobs:
            stats = step.stats or {}
            fraction = min(max(float(step.fraction), 0.0), 1.0)
            if key is not None and key in stats:
                count = int(stats[key])
                total = round(count / fraction) if fraction > 0 else None
            else:
                total = int(stats.get("target_patches") or stats.get("patches") or 0) \
                    if name == "patches" else 100
                total = total or 100
                count = round(fraction * total)
            if total is not None:
                progress_bar.total = max(total, count)
            progress_bar.update(count - progress_bar.n)
            if step.message:
                progress_bar.set_postfix_str(step.message, refresh=False)
            last = step
    if last is None:
        raise RuntimeError("offline render produced no result")
    return last


# ---------------------------------------------------------------- long steps of the CLI

SHOW_STEPS = False      # the CLI turns this on; the viewer and the library stay quiet
STEP_DELAY_S = 2.0      # a bar appears only for work that has run this long


def steps(items, total: int | None = None, desc: str = ""):
    """``items`` with a tqdm bar on stderr once the loop has run STEP_DELAY_S (CLI only)."""
    if not SHOW_STEPS or QUIET:
        return items
    from tqdm.auto import tqdm

    return tqdm(items, total=total, desc=desc, delay=STEP_DELAY_S, leave=False,
                mininterval=0.5, dynamic_ncols=True)


TICK_S = 0.5            # how often a busy line redraws its elapsed time


@contextmanager
def busy(desc: str):
    """One long step with no parts to count (reading one huge mesh file, building its normals):
    after STEP_DELAY_S a line ``desc ... 12.5 s`` on stderr ticks until the step ends, then it
    is cleared (CLI only; nothing for short steps)."""
    if not SHOW_STEPS or QUIET:
        yield
        return
    done = threading.Event()
    start = time.perf_counter()

    def tick() -> None:
        if done.wait(STEP_DELAY_S):
            return
        stream = sys.stderr
        width = 0
        while True:
            line = f"{desc} ... {time.perf_counter() - start:.1f} s"
            width = max(width, len(line))
            stream.write("\r" + line.ljust(width))
            stream.flush()
            if done.wait(TICK_S):
                break
        stream.write("\r" + " " * width + "\r")
        stream.flush()

    ticker = threading.Thread(target=tick, daemon=True, name="shadelab-busy")
    ticker.start()
    try:
        yield
    finally:
        done.set()
        ticker.join()
