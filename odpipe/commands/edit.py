"""``odpipe edit``: flag a TrackingTable file's rows with the edit reasons."""

from __future__ import annotations

import numpy as np

from odpipe.preprocess import store
from odpipe.preprocess.edit import EditConfig, edit

NAME = "edit"
HELP = "flag rows: elevation, duplicates, format validity, blunders, range modulus, short passes, arc"


def add_arguments(parser) -> None:
    parser.add_argument("input", help="TrackingTable Parquet (ramps read from IN.ramps.parquet if present)")
    parser.add_argument("-o", "--output", required=True, help="output Parquet")
    d = EditConfig()
    parser.add_argument("--min-elevation", type=float, default=np.degrees(d.min_elevation),
                        help="elevation mask, deg (needs an 'elevation_rx' column)")
    parser.add_argument("--blunder-k", type=float, default=d.blunder_k, help="robust sigmas of the detrended signal")
    parser.add_argument("--gross-k", type=float, default=d.gross_k, help="robust sigmas of a pass's values")
    parser.add_argument("--min-pass-samples", type=int, default=d.min_pass_samples)
    parser.add_argument("--max-gap", type=float, default=d.max_gap, help="pass break at gaps longer than this, s")
    parser.add_argument("--arc", nargs=2, metavar=("START", "END"), help="fit arc, UTC ISO times")


def run(args) -> int:
    table, ramps = store.read(args.input)
    cfg = EditConfig(min_elevation=np.radians(args.min_elevation), blunder_k=args.blunder_k, gross_k=args.gross_k,
                     min_pass_samples=args.min_pass_samples, max_gap=args.max_gap,
                     arc=tuple(args.arc) if args.arc else None)
    out, summary = edit(table, ramps, cfg)
    store.write(args.output, out, ramps)
    print(summary.to_string(index=False))
    return 0
