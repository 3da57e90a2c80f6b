"""CPU seconds of GRAIL-B's a priori orbit search (``initial_state.from_doppler`` of the nightly's start-up arc),
by step, and the state it finds (printed in full, to compare checkouts bit for bit; figures printed, never asserted).

    python benchmarks/grail_apriori.py [--repeat 3] [--config runs/grail_b_2012_04_09_start.toml]

Steps (:mod:`odpipe.od.apriori`): the rows (blunder edit and 60-s compression of the two-way Doppler),
the line of sight, the circular-orbit grid search, and the whole search as ``odpipe apriori`` runs it
(:func:`odpipe.pipeline.apriori.doppler_apriori`: ingest, rows, line of sight, grid, least squares through
the field, post-fit residuals). The first repeat also loads numba's cache and the files; the minimum of the
others is the figure. Run it on two checkouts in turn (interleaved) on a shared machine.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from odpipe.od import apriori as A  # noqa: E402
from odpipe.pipeline.apriori import doppler_apriori  # noqa: E402
from odpipe.pipeline.config import load_config  # noqa: E402
from odpipe.pipeline.ingest import ingest  # noqa: E402


def cpu(fn, *args, **kw):
    """(result, CPU s) of one call."""
    clock = time.process_time()
    out = fn(*args, **kw)
    return out, time.process_time() - clock


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--config", type=Path, default=ROOT / "runs" / "grail_b_2012_04_09_start.toml")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    cfg = load_config(args.config)
    data = ingest(list(cfg.data.files), spacecraft=cfg.arc.spacecraft)
    searched = {}
    search = A.circular_search

    def capture(*a, **kw):  # the grid search's inputs, to time it alone
        searched["args"] = a, kw
        return search(*a, **kw)

    A.circular_search = capture
    times = {"rows": [], "grid search": [], "whole search": []}
    for _ in range(args.repeat):
        times["rows"].append(cpu(A.doppler_rows, data.table, data.ramps, cfg.arc.spacecraft)[1])
        (result, _), t_all = cpu(doppler_apriori, cfg)
        times["whole search"].append(t_all)
        a, kw = searched["args"]
        times["grid search"].append(cpu(search, *a, **kw)[1])
    A.circular_search = search
    print(f"{ROOT.name}: {args.config.name}, CPU s (min of repeats 2..{args.repeat}; all)")
    for step, ts in times.items():
        best = min(ts[1:] or ts)
        print(f"  {step:13s} {best:6.2f}   " + " ".join(f"{t:.2f}" for t in ts))
    np.set_printoptions(precision=17)
    print(f"  epoch {result.epoch!r} TDB s, state {result.state.tolist()} m, m/s, post-fit {result.rms_los!r} m/s")


if __name__ == "__main__":
    main()
