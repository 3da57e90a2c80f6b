"""Time scales (UTC, TAI, TT, TDB, GPS) and tracking-format calendars.

Model time is TDB seconds past J2000 (float64) or the two-part form
``(whole int64 s, frac float64 s)`` for light-time precision; see
:mod:`odpipe.time.scales`.
"""

from odpipe.time.calendars import doy_to_utc, odf_seconds_to_utc, utc_to_doy, utc_to_odf_seconds
from odpipe.time.scales import (
    as_utc_ns,
    gps_seconds_to_utc,
    split_tdb,
    tai_minus_utc,
    tdb2_to_utc,
    tdb_minus_tt,
    tdb_to_tt_seconds,
    tdb_to_utc,
    tt_to_utc,
    utc_to_gps_seconds,
    utc_to_gps_week,
    utc_to_tai,
    utc_to_tdb,
    utc_to_tdb2,
    utc_to_tt,
)

__all__ = [
    "as_utc_ns", "doy_to_utc", "gps_seconds_to_utc", "odf_seconds_to_utc", "split_tdb", "tai_minus_utc",
    "tdb2_to_utc", "tdb_minus_tt", "tdb_to_tt_seconds", "tdb_to_utc", "tt_to_utc", "utc_to_doy",
    "utc_to_gps_seconds", "utc_to_gps_week", "utc_to_odf_seconds", "utc_to_tai", "utc_to_tdb",
    "utc_to_tdb2", "utc_to_tt",
]
