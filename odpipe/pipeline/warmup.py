"""Ahead-of-time numba compilation: ``python -m odpipe.pipeline.warmup`` (``make`` runs it at install).

Every numba kernel is cached on disk (``cache=True``), but a fresh checkout's cache is
empty, and the first demo would wait for the compiler. This runs the demo on the first
``DAYS`` days of its case in a temporary folder, with one worker: the same simulation,
readers, force models, fits, products and report on less data, so every kernel signature
the demo uses is compiled once into the checkout's cache. It prints the demo's own
compile line (functions and seconds, main process and worker) and the warm-up's wall time.
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

from odpipe.pipeline.demo import run_demo

DAYS = 11.0  # two station-keeping maneuvers (days 3.5 and 10.5) and an attitude burn: short and long arcs


def warm_up(days: float = DAYS) -> str:
    """Run the shortened demo in a temporary folder; one line on what was compiled."""
    t0 = time.perf_counter()
    lines: list[str] = []
    with tempfile.TemporaryDirectory(prefix="odpipe-warmup-") as tmp:
        run_demo(Path(tmp) / "demo", workers=1, progress=lines.append, days=days)
    note = next((line for line in lines if line.startswith("numba:")), "numba: no compile report")
    return f"warm-up on {days:g} days of the demo case, {time.perf_counter() - t0:.1f} s: {note}"


if __name__ == "__main__":
    print(warm_up())
    sys.exit(0)
