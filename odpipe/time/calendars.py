"""Calendar forms of UTC used by tracking formats: ODF seconds past 1950 and day of year.

ODF (TRK-2-18) time tags count seconds from 1950-01-01T00:00:00 UTC on the UTC
calendar, 86400 s per day (leap seconds are not counted, as in the ODF
integer-second tag convention).
"""

from __future__ import annotations

import numpy as np

from odpipe.constants import NS_PER_DAY, NS_PER_S

ODF_ORIGIN = np.datetime64("1950-01-01T00:00:00", "ns")


def odf_seconds_to_utc(seconds, fraction=0.0) -> np.ndarray:
    """UTC datetime64[ns] from ODF integer seconds past 1950-01-01 UTC plus a fraction (s)."""
    s = np.asarray(seconds)
    if s.dtype.kind == "f":
        whole = np.floor(s)
        fraction = np.asarray(fraction, dtype=float) + (s - whole)
        s = whole
    ns = s.astype(np.int64) * NS_PER_S + np.round(np.asarray(fraction, dtype=float) * 1e9).astype(np.int64)
    return ODF_ORIGIN + ns.astype("timedelta64[ns]")


def utc_to_odf_seconds(epoch_utc) -> tuple[np.ndarray, np.ndarray]:
    """(whole int64 s, fraction float64 s) past 1950-01-01 UTC, the ODF time tag."""
    ns = (np.asarray(epoch_utc).astype("datetime64[ns]") - ODF_ORIGIN).astype(np.int64)
    whole, rem = np.divmod(ns, NS_PER_S)
    return whole, rem * 1e-9


def doy_to_utc(year, doy, seconds_of_day=0.0) -> np.ndarray:
    """UTC datetime64[ns] from year, day of year (1 = Jan 1) and seconds of day."""
    year = np.asarray(year, dtype=np.int64)
    doy = np.asarray(doy, dtype=np.int64)
    if np.any((doy < 1) | (doy > 366)):
        raise ValueError(f"day of year out of 1..366: {np.asarray(doy)[(doy < 1) | (doy > 366)].ravel()[0]}")
    jan1 = (year - 1970).astype("datetime64[Y]").astype("datetime64[ns]")
    sod_ns = np.round(np.asarray(seconds_of_day, dtype=float) * 1e9).astype(np.int64)
    return jan1 + ((doy - 1) * NS_PER_DAY + sod_ns).astype("timedelta64[ns]")


def utc_to_doy(epoch_utc) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(year int64, day of year int64, seconds of day float64) of UTC epochs."""
    t = np.asarray(epoch_utc).astype("datetime64[ns]")
    year = t.astype("datetime64[Y]")
    day = t.astype("datetime64[D]")
    doy = (day - year.astype("datetime64[D]")).astype(np.int64) + 1
    sod = (t - day.astype("datetime64[ns]")).astype(np.int64) * 1e-9
    return year.astype(np.int64) + 1970, doy, sod
