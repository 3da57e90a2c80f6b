"""``odpipe compress``: Doppler compression of a TrackingTable file."""

from __future__ import annotations

import logging

from odpipe.commands._values import number

NAME = "compress"
HELP = "compress Doppler to a longer count time (exact averages / phase differences)"
log = logging.getLogger(__name__)


def add_arguments(parser) -> None:
    parser.add_argument("input", help="TrackingTable Parquet (ramps read from IN.ramps.parquet if present)")
    parser.add_argument("-o", "--output", required=True, help="output Parquet")
    parser.add_argument("--count-time", type=number(), default=60.0, help="target count time, s (default 60)")
    parser.add_argument("--partial", choices=("keep", "flag", "drop"), default="keep",
                        help="short windows: keep as shorter counts, flag them, or drop and report")
    parser.add_argument("--max-gap", type=number(), default=600.0, help="pass break at gaps longer than this, s")
    parser.add_argument("--ramp-delay", type=float,
                        help="s between a ramp change at the transmitter and its effect on the data (default: "
                             "the median round-trip light time of the rtlt_s column, as odpipe run uses; else 0)")


def run(args) -> int:
    from odpipe.commands._inputs import read_table   # the pipeline's imports: not for `odpipe compress --help`
    from odpipe.pipeline.geometry import median_round_trip
    from odpipe.preprocess import store
    from odpipe.preprocess.compress import compress

    table, ramps = read_table(args.input)
    delay = median_round_trip(table) if args.ramp_delay is None else args.ramp_delay
    if args.ramp_delay is None:
        log.info("ramp delay %.3f s (%s)", delay, "median rtlt_s" if "rtlt_s" in table else "no rtlt_s column")
    out, report = compress(table, args.count_time, ramps=ramps, partial=args.partial, max_gap=args.max_gap,
                           ramp_delay=delay)
    store.write(args.output, out, ramps)
    print("\n".join(report.lines()))
    return 0
