"""The contract between offline renderers (ray tracing, path tracing, radiosity) and their
consumers (the CLI's tqdm bar, the viewer's side panel, benchmarks).

An offline render is a generator that yields :class:`Progress` after each pass, tile or
iteration. The consumer cancels by closing the generator (``gen.close()``) or simply by not
asking for more; the renderer must stop promptly between chunks (keep chunks well under 0.2 s
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


def run_to_end(jobs: Iterator[Progress], desc: str = "", show: bool = True) -> Progress:
    """Drive a progressive job to completion with a tqdm bar; return the last Progress."""
    from tqdm import tqdm

    last = None
    with tqdm(total=1000, desc=desc, disable=not show, unit="‰", leave=False) as bar:
        for step in jobs:
            bar.update(int(step.fraction * 1000) - bar.n)
            if step.message:
                bar.set_postfix_str(step.message, refresh=False)
            last = step
    if last is None:
        raise RuntimeError("offline render produced no result")
    return last


# ---------------------------------------------------------------- long steps of the CLI

SHOW_STEPS = False      # the CLI turns this on; the viewer and the library stay quiet
STEP_DELAY_S = 2.0      # a bar appears only for work that has run this long


def steps(items, total: int | None = None, desc: str = ""):
    """``items`` with a tqdm bar on stderr once the loop has run STEP_DELAY_S (CLI only)."""
    if not SHOW_STEPS:
        return items
    from tqdm import tqdm

    return tqdm(items, total=total, desc=desc, delay=STEP_DELAY_S, leave=False,
                mininterval=0.5, dynamic_ncols=True)


TICK_S = 0.5            # how often a busy line redraws its elapsed time


@contextmanager
def busy(desc: str):
    """One long step with no parts to count (reading one huge mesh file, building its normals):
    after STEP_DELAY_S a line ``desc ... 12.5 s`` on stderr ticks until the step ends, then it
    is cleared (CLI only; nothing for short steps)."""
    if not SHOW_STEPS:
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
