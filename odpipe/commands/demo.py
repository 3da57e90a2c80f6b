"""odpipe demo: the embedded ARTEMIS-like case end to end (what `make demo` runs)."""

import logging
import time
from pathlib import Path

from odpipe.commands._values import number
from odpipe.errors import Exit

NAME = "demo"
HELP = "simulate the embedded ARTEMIS-like case, fit short and long arcs, overlaps, maneuvers, truth comparison"

_log = logging.getLogger(__name__)


def add_arguments(p):
    p.add_argument("-o", "--out", type=Path, default=Path("out/demo"), help="output folder")
    p.add_argument("--workers", type=number(int), default=2, help="local Dask workers")
    p.add_argument("--twin", action="store_true",
                   help="the ARTEMIS-P2 twin with the thesis' error budget (runs/artemis_p2_twin.toml, 1-3 min)")


def run(args) -> int:
    from odpipe.pipeline.demo import TWIN, run_demo
    from odpipe.simulate.case import load

    t0 = time.perf_counter()
    headline = run_demo(args.out, args.workers, progress=_log.info, case=load(TWIN) if args.twin else None)
    print("\n".join(f"{k}: {v}" for k, v in headline.items()))
    _log.info("demo finished in %.0f s; open %s", time.perf_counter() - t0, headline["report"])
    return Exit.OK
