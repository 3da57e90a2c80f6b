"""Long fuzzing run of every reader (tests/fuzzing.py): inputs, ParseErrors and crashes per reader.

Each input is a seeded mutation of a real file (or of the project's writers' output) read in
"raise" mode (ParseError: refused), and again in "report" mode when it was refused (refused:
still refused whole, a file-level fault; reported: read with its bad records reported). A crash is any exception other
than ParseError, or an input not answered within ``--limit`` seconds; the run stops at the
first one and prints it. Figures are reported, never asserted.

    python benchmarks/bench_fuzz.py --inputs 100000            # every reader
    python benchmarks/bench_fuzz.py --inputs 10000 --readers oem ionex --seed 3
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.conftest import SHARED_DATA  # noqa: E402
from tests.fuzzing import READERS, Crash, run  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--inputs", type=int, default=1000, help="mutated inputs per reader (default 1000)")
    ap.add_argument("--readers", nargs="+", choices=sorted(READERS), default=sorted(READERS))
    ap.add_argument("--seed", type=int, default=0, help="seed of the mutations (default 0)")
    ap.add_argument("--limit", type=float, default=10.0, help="seconds one input may take (default 10)")
    args = ap.parse_args(argv)
    if not SHARED_DATA.is_dir():
        print(f"real data folder {SHARED_DATA} is absent")
        return 1
    print(f"{'reader':14s} {'inputs':>8s} {'ParseError':>10s} {'refused':>8s} {'reported':>9s} {'crashes':>7s} "
          f"{'CPU s':>7s} {'ms/input':>8s}", flush=True)
    crashed = 0
    for name in args.readers:
        try:
            t = run(name, SHARED_DATA, args.inputs, seed=args.seed, limit_s=args.limit)
        except Crash as exc:
            print(f"{name:14s} CRASH: {exc}", flush=True)
            crashed += 1
            continue
        print(f"{name:14s} {t.inputs:8d} {t.parse_errors:10d} {t.refused:8d} {t.reported:9d} {0:7d} {t.seconds:7.1f} "
              f"{1e3 * t.seconds / max(t.inputs, 1):8.2f}", flush=True)
    return 1 if crashed else 0


if __name__ == "__main__":
    sys.exit(main())
