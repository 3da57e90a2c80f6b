"""CCSDS Orbit Ephemeris Message (OEM 2.0, KVN) writer.

States are written in km and km/s, covariances (lower triangle, 21 numbers)
in km², km²/s, km²/s², in ICRF axes about the segment's centre. Epochs are in
TDB (the models' scale, default) or UTC.
"""

from __future__ import annotations

from datetime import datetime, timezone

import numpy as np

from odpipe.constants import J2000
from parsers.atomic import write_text
from odpipe.products.segments import EphemerisSegment
from odpipe.time import tdb_to_utc

_TRIL = np.tril_indices(6)


def epoch_strings(t_tdb, time_system: str = "TDB") -> list[str]:
    """ISO calendar strings of TDB seconds past J2000, in TDB or UTC, rounded to the nearest µs (an
    epoch on a whole µs reads back as the same double: see :func:`odpipe.pipeline.fitted_trajectory.fitted_segments`)."""
    t_tdb = np.atleast_1d(np.asarray(t_tdb, dtype=float))
    if time_system == "TDB":
        # The TDB calendar has no leap seconds: plain arithmetic from J2000.
        whole = np.floor(t_tdb)
        ns = (whole.astype(np.int64) * 1_000_000_000 + np.round((t_tdb - whole) * 1e9).astype(np.int64))
        epochs = J2000 + ns.astype("timedelta64[ns]")
    elif time_system == "UTC":
        epochs = np.asarray(tdb_to_utc(t_tdb), dtype="datetime64[ns]")
    else:
        raise ValueError(f"OEM time system must be TDB or UTC, not {time_system!r}")
    ns = epochs.astype("datetime64[ns]").astype(np.int64)
    return [str(e) for e in ((ns + 500) // 1000).astype("datetime64[us]")]


def format_oem(segments: list[EphemerisSegment], object_name: str, object_id: str, *,
               time_system: str = "TDB", originator: str = "odpipe", interpolation_degree: int = 7,
               comments: list[str] = (), creation_date: str | None = None) -> str:
    """The text of an OEM with one data block (and covariance block) per segment; ``comments`` (e.g.
    the run's provenance) become COMMENT lines of the header.

    ``creation_date`` (ISO, UTC) defaults to now; give one for byte-reproducible files."""
    created = creation_date or datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%S")
    out = ["CCSDS_OEM_VERS = 2.0", *[f"COMMENT {c}" for c in comments], f"CREATION_DATE = {created}",
           f"ORIGINATOR = {originator}", ""]
    for seg in segments:
        epochs = epoch_strings(seg.t_tdb, time_system)
        out += ["META_START", f"OBJECT_NAME = {object_name}", f"OBJECT_ID = {object_id}",
                f"CENTER_NAME = {seg.center.upper()}", "REF_FRAME = ICRF", f"TIME_SYSTEM = {time_system}",
                f"START_TIME = {epochs[0]}", f"STOP_TIME = {epochs[-1]}", "INTERPOLATION = HERMITE",
                f"INTERPOLATION_DEGREE = {interpolation_degree}", "META_STOP", ""]
        km = seg.states / 1e3
        out += [f"{e} " + " ".join(f"{v: .16e}" for v in row) for e, row in zip(epochs, km)]
        out.append("")
        if seg.covariances is not None:
            out += ["COVARIANCE_START"]
            for e, cov in zip(epoch_strings(seg.covariance_t_tdb, time_system), seg.covariances / 1e6):
                out += [f"EPOCH = {e}", "COV_REF_FRAME = ICRF"]
                low = cov[_TRIL]
                k = 0
                for i in range(6):
                    out.append(" ".join(f"{v: .16e}" for v in low[k:k + i + 1]))
                    k += i + 1
            out += ["COVARIANCE_STOP", ""]
    return "\n".join(out)


def write_oem(path, segments: list[EphemerisSegment], object_name: str, object_id: str, **kwargs):
    """Write an OEM atomically (see :func:`format_oem` for the options); returns the path."""
    return write_text(path, format_oem(segments, object_name, object_id, **kwargs))
