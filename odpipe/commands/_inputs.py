"""What the step-by-step commands read: TrackingTable files and the reference trajectory for geometry.

The media corrections and the elevation mask need each row's spacecraft
direction and light time. ``odpipe run`` takes them from its a priori
trajectory; a step command takes them from ``--trajectory`` (a CCSDS OEM, an
SPK, or an odpipe run directory) through the same code
(:mod:`odpipe.pipeline.geometry`), or from the columns an earlier step wrote.
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from odpipe.preprocess import store

log = logging.getLogger(__name__)
PARQUET_MAGIC = b"PAR1"


def read_table(path):
    """(table, ramps or None) of a TrackingTable Parquet file; ValueError naming the file otherwise."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: no such file")
    with open(path, "rb") as f:
        head = f.read(4)
    if head != PARQUET_MAGIC:
        raise ValueError(f"{path}: not a Parquet file; expected a TrackingTable .parquet "
                         "(make one from a tracking file with `odpipe convert FILE -o OUT.parquet`)")
    try:
        return store.read(path)
    except ValueError as err:     # pyarrow's ArrowInvalid is a ValueError too; its text repeats the path
        reason = str(err).split(f"{path}': ", 1)[-1]
        raise ValueError(f"{path}: not a readable Parquet file ({reason})") from None


def add_geometry_arguments(parser) -> None:
    parser.add_argument("--trajectory", help="reference trajectory for the geometry (elevation, azimuth, light "
                        "time): a CCSDS OEM, an SPK, or an odpipe run directory (its trajectory.oem); "
                        "needed unless the table has elevation_rx/azimuth_rx/rtlt_s columns")
    parser.add_argument("--naif-id", type=int, help="the SPK's body (NAIF id) when it holds several")
    parser.add_argument("--ephemeris", default="de440",
                        help="JPL ephemeris (name or .bsp) placing a trajectory not about Earth (default de440)")
    parser.add_argument("--spacecraft", help="keep only this spacecraft's rows (needed with --trajectory "
                        "when the table holds several spacecraft)")
    parser.add_argument("--stations", help="extra station CSV for the catalog")


def utc_times(texts, option: str):
    """datetime64[ns] of ISO UTC strings given to ``option``; ValueError naming it."""
    try:
        return tuple(np.datetime64(t, "ns") for t in texts)
    except ValueError:
        raise ValueError(f"{option}: {' '.join(texts)!r} are not ISO UTC times (e.g. 2006-02-27T03:00)") from None


def catalog(args):
    from odpipe.environment.stations import StationCatalog

    cat = StationCatalog.default()
    return cat.with_csv(args.stations) if args.stations else cat


def select_spacecraft(table, args, table_path):
    """The rows of ``--spacecraft`` (all rows when not given); ValueError when it has none."""
    if args.spacecraft is None:
        return table
    spacecraft = table["spacecraft"].astype(str)
    keep = (spacecraft == args.spacecraft).to_numpy()
    if not keep.any():
        raise ValueError(f"{table_path}: no rows of spacecraft {args.spacecraft!r} "
                         f"(it holds {sorted(spacecraft.unique())})")
    log.info("%s: %d rows of spacecraft %s kept, %d of others left out", table_path, keep.sum(),
             args.spacecraft, (~keep).sum())
    return table[keep].reset_index(drop=True)


def with_geometry(table, args, table_path, purpose: str, *, arc=None, allow_gaps: bool = False):
    """(table with geometry columns, ``target_itrs`` or None) for ``purpose`` (e.g. "media corrections").
    Call :func:`select_spacecraft` first.

    With ``--trajectory`` the geometry is computed (replacing any in the table), and every row of a
    known station inside ``arc`` ((start, end) UTC, or the whole table) must get it unless
    ``allow_gaps``; without, the table's own columns serve. ValueError names what is missing.
    """
    from odpipe.pipeline.geometry import add_geometry, apparent_itrs, load_trajectory, span_utc

    if args.trajectory is None:
        if "elevation_rx" not in table or "rtlt_s" not in table:
            raise ValueError(f"{table_path}: no geometry (elevation_rx, rtlt_s columns) for the {purpose}: "
                             "give --trajectory (an OEM, an SPK or an odpipe run directory)")
        return table, None
    spacecraft = table["spacecraft"].astype(str).unique()
    if len(spacecraft) > 1:
        raise ValueError(f"{table_path}: holds spacecraft {sorted(spacecraft)}; the trajectory is "
                         "one spacecraft's: name it with --spacecraft")
    traj = load_trajectory(args.trajectory, args.naif_id)
    eph = None
    if traj.center != "earth":
        from odpipe.environment.ephemeris import Ephemeris
        eph = Ephemeris.open(args.ephemeris)
    cat = catalog(args)
    out = add_geometry(table, traj, eph, cat)
    start, end = span_utc(traj)
    epoch = out["epoch"].to_numpy("datetime64[ns]")
    need = np.array([s in cat for s in out["station_rx"].astype(str)])
    if arc is not None:
        need &= (epoch >= np.datetime64(arc[0], "ns")) & (epoch <= np.datetime64(arc[1], "ns"))
    missing = need & ~np.isfinite(out["elevation_rx"].to_numpy(float))
    if missing.any():
        msg = (f"{args.trajectory}: spans {start} .. {end} UTC; {int(missing.sum())} rows of {table_path} "
               f"({np.datetime64(epoch[missing].min(), 's')} .. {np.datetime64(epoch[missing].max(), 's')} UTC) "
               "get no geometry from it (their signal left the spacecraft outside that span)")
        if not allow_gaps:
            raise ValueError(msg)
        log.warning("%s; they get no correction", msg)
    log.info("geometry for the %s: elevation, azimuth and light time from %s (%s .. %s UTC)", purpose,
             args.trajectory, start, end)
    return out, apparent_itrs(traj, eph)
