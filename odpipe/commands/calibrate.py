"""``odpipe calibrate``: add troposphere/ionosphere corrections to a TrackingTable Parquet file.

The corrections are those ``odpipe run`` applies (:func:`odpipe.media.apply.calibrate`), with the
spacecraft direction from ``--trajectory`` at every leg's own instant. Calibration files that do not
cover the data, and rows whose correction would be a model fallback or missing, are errors unless
``--allow-fallbacks`` is given; then each fallback is logged per pass.
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from odpipe.commands._inputs import add_geometry_arguments, catalog, read_table, select_spacecraft, with_geometry
from parsers.atomic import write_csv

NAME = "calibrate"
HELP = "apply media calibrations (TRK-2-23 .TRO/.ION, IONEX) to a TrackingTable Parquet file"
log = logging.getLogger(__name__)


def add_arguments(parser) -> None:
    parser.add_argument("table", help="TrackingTable .parquet (ramps read from TABLE.ramps.parquet if present)")
    parser.add_argument("--tro", action="append", default=[], help="TRK-2-23 troposphere file (repeatable)")
    parser.add_argument("--ion", action="append", default=[], help="TRK-2-23 ionosphere file (repeatable)")
    parser.add_argument("--ionex", action="append", default=[], help="IONEX file (repeatable, combined in time)")
    add_geometry_arguments(parser)
    parser.add_argument("--ramps", help="uplink ramp table .parquet (default: the one beside TABLE)")
    parser.add_argument("--order", type=int, default=10, help="per-pass smoothing polynomial order (-1: none)")
    parser.add_argument("--allow-fallbacks", action="store_true",
                        help="accept calibration files that do not cover the data, model fallbacks (seasonal "
                             "troposphere, no ionosphere, standard atmosphere) and rows left without a "
                             "correction (NaN); each is logged per pass")
    parser.add_argument("-o", "--output", required=True, help="output .parquet (written atomically, ramps beside)")
    parser.add_argument("--report", help="per-pass coverage report CSV")
    parser.add_argument("--plots", help="directory for one delay PNG per pass")


def run(args) -> int:
    import pandas as pd

    from odpipe.media.apply import calibrate, fallbacks
    from odpipe.media.ionosphere import IonexModel
    from odpipe.media.model import MediaModel
    from odpipe.media.plot import plot_pass_delays
    from odpipe.preprocess import store
    from parsers.ionex import read_ionex
    from parsers.trk223 import read_trk223

    table, ramps = read_table(args.table)
    if args.ramps:
        ramps = pd.read_parquet(args.ramps)
    table = select_spacecraft(table, args, args.table)
    table, target = with_geometry(table, args, args.table, "media corrections", allow_gaps=args.allow_fallbacks)
    calibrations = read_trk223(*args.tro, *args.ion)
    maps = read_ionex(*args.ionex) if args.ionex else None
    _check_coverage(table, calibrations, maps, args)
    model = MediaModel(calibrations, IonexModel(maps) if maps is not None else None)
    out, report = calibrate(table, model, target_itrs=target, catalog=catalog(args), ramps=ramps,
                            order=None if args.order < 0 else args.order)
    used = fallbacks(out)
    if len(used) and not args.allow_fallbacks:
        reasons = used.groupby("reason", sort=False)["rows"].sum()
        hint = "; give --trajectory" if target is None and any("direction" in r for r in reasons.index) else ""
        raise ValueError(f"{args.table}: {', '.join(f'{n} rows {r}' for r, n in reasons.items())} "
                         f"({used['pass_id'].nunique()} of {len(report)} passes){hint}; "
                         "pass --allow-fallbacks to accept (each is then logged per pass)")
    for r in used.itertuples(index=False):
        log.warning("pass %d (%s %s, %s .. %s UTC): %s: %d of %d rows", r.pass_id, r.station_rx, r.observable,
                    np.datetime64(r.start, "s"), np.datetime64(r.end, "s"), r.reason, r.rows, r.of)
    store.write(args.output, out, ramps)
    if args.report:
        write_csv(args.report, report, index=False)
    if args.plots:
        Path(args.plots).mkdir(parents=True, exist_ok=True)
        for pid in report["pass_id"]:
            plot_pass_delays(out, pid, Path(args.plots) / f"media_pass_{pid}.png")
    print(f"{len(out)} rows, {len(report)} passes calibrated; {int(np.isfinite(out['media_m']).sum())} rows "
          f"corrected; {used['pass_id'].nunique()} passes with fallbacks")
    return 0


def _check_coverage(table, calibrations, maps, args) -> None:
    """Each kind of calibration file given must cover the data's span (raise, or log with fallbacks)."""
    from odpipe.media.coverage import ionex_span, trk223_spans, uncovered_message

    start, end = table["epoch"].min(), table["epoch"].max()
    problems = [uncovered_message("troposphere (--tro)", trk223_spans(calibrations, args.tro), start, end),
                uncovered_message("ionosphere (--ion)", trk223_spans(calibrations, args.ion), start, end)]
    if maps is not None:
        problems.append(uncovered_message("ionosphere (--ionex)", {", ".join(args.ionex): ionex_span(maps)},
                                          start, end))
    for msg in filter(None, problems):
        if not args.allow_fallbacks:
            raise ValueError(f"{msg}; pass --allow-fallbacks to use the models there")
        log.warning("%s: models used there", msg)
