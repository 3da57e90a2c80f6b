"""odpipe demo: the embedded ARTEMIS-like case end to end (what `make demo` runs)."""

import time
from pathlib import Path

from odpipe.pipeline.demo import run_demo

NAME = "demo"
HELP = "simulate the embedded ARTEMIS-like case, fit short and long arcs, overlaps, maneuvers, truth comparison"


def add_arguments(p):
    p.add_argument("-o", "--out", type=Path, default=Path("out/demo"), help="output folder")
    p.add_argument("--workers", type=int, default=2, help="local Dask workers")


def run(args) -> int:
    t0 = time.perf_counter()
    headline = run_demo(args.out, args.workers)
    print("\n".join(f"{k}: {v}" for k, v in headline.items()))
    print(f"demo finished in {time.perf_counter() - t0:.0f} s; open {headline['report']}")
    return 0
