"""``odpipe calibrate``: add troposphere/ionosphere corrections to a TrackingTable Parquet file."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from odpipe.products.atomic import write_csv, write_parquet

NAME = "calibrate"
HELP = "apply media calibrations (TRK-2-23 .TRO/.ION, IONEX) to a TrackingTable Parquet file"


def add_arguments(parser) -> None:
    parser.add_argument("table", help="TrackingTable .parquet (needs elevation_rx/azimuth_rx columns, rad)")
    parser.add_argument("--tro", action="append", default=[], help="TRK-2-23 troposphere file (repeatable)")
    parser.add_argument("--ion", action="append", default=[], help="TRK-2-23 ionosphere file (repeatable)")
    parser.add_argument("--ionex", action="append", default=[], help="IONEX file (repeatable, combined in time)")
    parser.add_argument("--ramps", help="uplink ramp table .parquet travelling beside the table")
    parser.add_argument("--stations", help="extra station CSV for the catalog")
    parser.add_argument("--order", type=int, default=10, help="per-pass smoothing polynomial order (-1: none)")
    parser.add_argument("-o", "--output", required=True, help="output .parquet (written atomically)")
    parser.add_argument("--report", help="per-pass coverage report CSV")
    parser.add_argument("--plots", help="directory for one delay PNG per pass")


def run(args) -> int:
    from odpipe.environment.stations import StationCatalog
    from odpipe.media.apply import calibrate
    from odpipe.media.ionosphere import IonexModel
    from odpipe.media.model import MediaModel
    from odpipe.media.plot import plot_pass_delays
    from parsers.ionex import read_ionex
    from parsers.trk223 import read_trk223

    table = pd.read_parquet(args.table)
    model = MediaModel(read_trk223(*args.tro, *args.ion),
                       IonexModel(read_ionex(*args.ionex)) if args.ionex else None)
    catalog = StationCatalog.default()
    if args.stations:
        catalog = catalog.with_csv(args.stations)
    ramps = pd.read_parquet(args.ramps) if args.ramps else None
    out, report = calibrate(table, model, catalog=catalog, ramps=ramps, order=None if args.order < 0 else args.order)
    write_parquet(args.output, out)
    if args.report:
        write_csv(args.report, report, index=False)
    if args.plots:
        Path(args.plots).mkdir(parents=True, exist_ok=True)
        for pid in report["pass_id"]:
            plot_pass_delays(out, pid, Path(args.plots) / f"media_pass_{pid}.png")
    flagged = int((report["notes"] != "").sum())
    print(f"{len(out)} rows, {len(report)} passes calibrated; {flagged} passes with fallbacks (see notes)")
    return 0
