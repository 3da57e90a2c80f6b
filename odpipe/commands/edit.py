"""``odpipe edit``: flag a TrackingTable file's rows with the edit reasons.

The elevation mask needs each row's elevation: from ``--trajectory`` (as ``odpipe calibrate``
computes it), or the ``elevation_rx`` column an earlier step wrote; with neither the command refuses
unless ``--no-elevation-mask`` says to edit without it.
"""

from __future__ import annotations

import logging

import numpy as np

from odpipe.commands._inputs import add_geometry_arguments, read_table, select_spacecraft, utc_times, with_geometry
from odpipe.commands._values import number
from odpipe.preprocess import store
from odpipe.preprocess.edit import EditConfig, edit

NAME = "edit"
HELP = "flag rows: elevation, duplicates, format validity, blunders, range modulus, short passes, arc"
log = logging.getLogger(__name__)


def add_arguments(parser) -> None:
    parser.add_argument("input", help="TrackingTable Parquet (ramps read from IN.ramps.parquet if present)")
    parser.add_argument("-o", "--output", required=True, help="output Parquet")
    d = EditConfig()
    parser.add_argument("--min-elevation", type=float, default=np.degrees(d.min_elevation),
                        help="elevation mask, deg (elevation from --trajectory or the 'elevation_rx' column)")
    parser.add_argument("--blunder-k", type=number(), default=d.blunder_k, help="robust sigmas of the detrended signal")
    parser.add_argument("--gross-k", type=number(), default=d.gross_k, help="robust sigmas of a pass's values")
    parser.add_argument("--min-pass-samples", type=number(int), default=d.min_pass_samples,
                        help="passes with fewer rows are flagged short_pass")
    parser.add_argument("--max-gap", type=number(), default=d.max_gap, help="pass break at gaps longer than this, s")
    parser.add_argument("--arc", nargs=2, metavar=("START", "END"), help="fit arc, UTC ISO times")
    parser.add_argument("--no-elevation-mask", action="store_true",
                        help="edit without the elevation mask (when no geometry is known; logged)")
    add_geometry_arguments(parser)


def run(args) -> int:
    table, ramps = read_table(args.input)
    table = select_spacecraft(table, args, args.input)
    arc = utc_times(args.arc, "--arc") if args.arc else None
    if arc is not None and not arc[1] > arc[0]:
        raise ValueError(f"--arc: END {args.arc[1]} is not after START {args.arc[0]}")
    if args.no_elevation_mask:
        if args.trajectory:
            raise ValueError("--no-elevation-mask and --trajectory contradict each other: give one")
        log.warning("%s: elevation mask not applied (--no-elevation-mask)", args.input)
    else:
        table, _ = with_geometry(table, args, args.input, "elevation mask", arc=arc)
    mask = -np.inf if args.no_elevation_mask else np.radians(args.min_elevation)
    cfg = EditConfig(min_elevation=mask, blunder_k=args.blunder_k, gross_k=args.gross_k,
                     min_pass_samples=args.min_pass_samples, max_gap=args.max_gap, arc=arc)
    out, summary = edit(table, ramps, cfg)
    store.write(args.output, out, ramps)
    print(summary.to_string(index=False))
    return 0
