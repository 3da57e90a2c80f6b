"""Time scales UTC, TAI, TT, TDB and GPS, and the model time of odpipe.

Model time is **TDB seconds past J2000** (J2000 = 2000-01-01T12:00:00 TDB).
As float64 it resolves about 0.12 µs in the 2000s–2020s; for light-time and
Doppler work use the two-part form ``(whole, frac)``: ``whole`` int64 seconds
and ``frac`` float64 seconds in [0, 1), so that ``t = whole + frac`` holds to
better than 1e-15 s in ``frac``.

UTC epochs are ``numpy.datetime64`` (any unit; converted to ns) scalars or
arrays. Conversions go through int64 nanoseconds, so UTC→TAI→TT is exact.
TDB−TT is the Fairhead & Bretagnon series as implemented by ERFA ``dtdb``
(geocentric by default; the topocentric terms when a station position is
given).
"""

from __future__ import annotations

import erfa
import numpy as np

from odpipe.constants import (GPS_MINUS_TAI_NS, GPS_ORIGIN_NS, J2000_JD, J2000_NS, NS_PER_DAY, NS_PER_S,
                              SECONDS_PER_DAY, TT_MINUS_TAI_NS)
from odpipe.numerics.interpolation import lagrange4_uniform
from parsers.leap_seconds import tai_minus_utc_ns, utc_ns_from_tai_ns


def as_utc_ns(epoch_utc) -> np.ndarray:
    """UTC epochs (datetime64 / ISO strings / pandas) as int64 ns since 1970."""
    arr = np.asarray(epoch_utc)
    if arr.dtype.kind in "OUS":
        arr = arr.astype("datetime64[ns]")
    if arr.dtype.kind != "M":
        raise TypeError(f"UTC epochs must be datetime64, got dtype {arr.dtype}")
    ns = arr.astype("datetime64[ns]")
    if np.any(np.isnat(ns)):
        raise ValueError("UTC epochs contain NaT")
    return ns.astype(np.int64)


def tai_minus_utc(epoch_utc) -> np.ndarray:
    """TAI−UTC in s (float64) at UTC epochs (from the IERS leap-second file)."""
    return tai_minus_utc_ns(as_utc_ns(epoch_utc)) / NS_PER_S


def utc_to_tai(epoch_utc) -> np.ndarray:
    """TAI as datetime64[ns] (a TAI calendar reading) from UTC epochs."""
    ns = as_utc_ns(epoch_utc)
    return (ns + tai_minus_utc_ns(ns)).astype("datetime64[ns]")


def utc_to_tt(epoch_utc) -> np.ndarray:
    """TT as datetime64[ns] (a TT calendar reading) from UTC epochs."""
    ns = as_utc_ns(epoch_utc)
    return (ns + tai_minus_utc_ns(ns) + TT_MINUS_TAI_NS).astype("datetime64[ns]")


def tt_to_utc(epoch_tt) -> np.ndarray:
    """UTC datetime64[ns] from TT calendar readings (datetime64)."""
    tt = np.asarray(epoch_tt).astype("datetime64[ns]").astype(np.int64)
    return utc_ns_from_tai_ns(tt - TT_MINUS_TAI_NS).astype("datetime64[ns]")


def _station_terms(station_itrs):
    """ERFA dtdb arguments (elong rad, u km, v km) for an ITRS position in m."""
    r = np.asarray(station_itrs, dtype=float)
    x, y, z = r[..., 0], r[..., 1], r[..., 2]
    return np.arctan2(y, x), np.hypot(x, y) / 1e3, z / 1e3


class _HourlyGeocentricDtdb:
    """The geocentric TDB-TT series (ERFA dtdb) at whole TT hours, computed once per hour and kept.

    Its shortest terms are far longer than an hour, so cubic interpolation between the
    hourly values errs by < 1e-15 s; the light-time loops ask for the same hours many times.
    A request beyond the kept hours computes only the hours it adds (a month-by-month batch
    over years costs the series once per hour, not once per hour per month).
    """

    PAD_H, MAX_H = 240, 24 * 366 * 5  # hours added around a request; longest span kept

    def __init__(self):
        self.first, self.values = 0, np.empty(0)

    def __call__(self, tt_days: np.ndarray) -> np.ndarray:
        hours = np.asarray(tt_days, dtype=float) * 24.0
        lo, hi = int(np.floor(hours.min())) - 2, int(np.ceil(hours.max())) + 3
        last = self.first + self.values.size - 1
        if not self.values.size or lo < self.first or hi > last:
            if hi - lo + 2 * self.PAD_H > self.MAX_H:  # epochs over many years: the series at each one
                return erfa.dtdb(J2000_JD, hours / 24.0, 0.0, 0.0, 0.0, 0.0)
            self._cover(lo - self.PAD_H, hi + self.PAD_H)
        return lagrange4_uniform(float(self.first), 1.0, self.values, hours)

    def _cover(self, lo: int, hi: int) -> None:
        """Keep the hours lo..hi, adding to the kept span while it stays within MAX_H."""
        last = self.first + self.values.size - 1
        if not self.values.size or max(hi, last) - min(lo, self.first) > self.MAX_H:
            self.first, self.values = lo, self._series(lo, hi)
            return
        before = self._series(lo, self.first - 1)
        after = self._series(last + 1, hi)
        self.first, self.values = min(lo, self.first), np.concatenate([before, self.values, after])

    @staticmethod
    def _series(lo: int, hi: int) -> np.ndarray:
        """ERFA dtdb (s) at TT hours lo..hi past J2000 (empty when hi < lo)."""
        return erfa.dtdb(J2000_JD, np.arange(lo, hi + 1, dtype=float) / 24.0, 0.0, 0.0, 0.0, 0.0)


_geocentric_dtdb = _HourlyGeocentricDtdb()


def _dtdb(tt_days_j2000, ut_fraction, station_itrs):
    """ERFA dtdb; the geocentric series (no diurnal terms) from hourly values (:class:`_HourlyGeocentricDtdb`)."""
    if station_itrs is None:
        t = np.asarray(tt_days_j2000, dtype=float)
        if t.size < 8:
            return erfa.dtdb(J2000_JD, t, 0.0, 0.0, 0.0, 0.0)
        return _geocentric_dtdb(t.ravel()).reshape(t.shape)
    elong, u, v = _station_terms(station_itrs)
    return erfa.dtdb(J2000_JD, tt_days_j2000, ut_fraction, elong, u, v)


def tdb_minus_tt(t_tdb, station_itrs=None) -> np.ndarray:
    """TDB−TT in s at TDB seconds past J2000 (ERFA dtdb).

    ``station_itrs`` (m, shape (3,) or (N,3)) adds the observer-dependent
    terms (≈2 µs diurnal); by default the geocentric value is returned.
    """
    t = np.asarray(t_tdb, dtype=float)
    ut_frac = np.mod(t / SECONDS_PER_DAY + 0.5, 1.0)  # UT ≈ TDB to ~70 s: enough for the µs topocentric term
    return _dtdb(t / SECONDS_PER_DAY, ut_frac, station_itrs)


def utc_to_tdb2(epoch_utc, station_itrs=None) -> tuple[np.ndarray, np.ndarray]:
    """Two-part TDB seconds past J2000 ``(whole int64, frac float64 in [0,1))`` from UTC."""
    utc = as_utc_ns(epoch_utc)
    tt_since = utc + tai_minus_utc_ns(utc) + TT_MINUS_TAI_NS - J2000_NS
    whole, rem_ns = np.divmod(tt_since, NS_PER_S)
    ut_frac = np.mod(utc, NS_PER_DAY) / NS_PER_DAY
    frac = rem_ns * 1e-9 + _dtdb(tt_since / NS_PER_DAY, ut_frac, station_itrs)
    carry = np.floor(frac).astype(np.int64)
    return whole + carry, frac - carry


def utc_to_tdb(epoch_utc, station_itrs=None) -> np.ndarray:
    """TDB seconds past J2000 (float64) from UTC epochs."""
    whole, frac = utc_to_tdb2(epoch_utc, station_itrs)
    return whole + frac


def split_tdb(t_tdb) -> tuple[np.ndarray, np.ndarray]:
    """Two-part form ``(whole int64, frac float64)`` of float TDB s (exact split)."""
    t = np.asarray(t_tdb, dtype=float)
    if not np.all(np.isfinite(t)):
        raise ValueError("TDB epochs contain NaN or infinity")
    whole = np.floor(t)
    return whole.astype(np.int64), t - whole


def tdb2_to_utc(whole, frac, station_itrs=None) -> np.ndarray:
    """UTC datetime64[ns] (rounded to the ns) from two-part TDB s past J2000."""
    whole = np.asarray(whole, dtype=np.int64)
    frac = np.asarray(frac, dtype=float)
    t_approx = whole + frac
    d = tdb_minus_tt(t_approx, station_itrs)
    d = tdb_minus_tt(t_approx - d, station_itrs)  # fixed point: d(TDB-TT)/dt ~ 1e-8
    frac_tt = frac - d
    tt_ns = whole * NS_PER_S + np.round(frac_tt * 1e9).astype(np.int64) + J2000_NS
    return utc_ns_from_tai_ns(tt_ns - TT_MINUS_TAI_NS).astype("datetime64[ns]")


def tdb_to_utc(t_tdb, station_itrs=None) -> np.ndarray:
    """UTC datetime64[ns] from TDB seconds past J2000 (float64)."""
    return tdb2_to_utc(*split_tdb(t_tdb), station_itrs=station_itrs)


def tdb_to_tt_seconds(t_tdb) -> np.ndarray:
    """TT seconds past J2000 TT (float64) from TDB seconds past J2000."""
    t = np.asarray(t_tdb, dtype=float)
    tt = t.copy()
    for _ in range(2):
        tt = t - tdb_minus_tt(tt)
    return tt


def utc_to_gps_seconds(epoch_utc) -> np.ndarray:
    """GPS seconds since 1980-01-06T00:00:00 GPS (float64) from UTC epochs."""
    ns = as_utc_ns(epoch_utc)
    gps = ns + tai_minus_utc_ns(ns) + GPS_MINUS_TAI_NS
    return (gps - GPS_ORIGIN_NS) / NS_PER_S


def gps_seconds_to_utc(gps_seconds) -> np.ndarray:
    """UTC datetime64[ns] from GPS seconds since 1980-01-06 (GPS = TAI − 19 s)."""
    g = np.asarray(gps_seconds, dtype=float)
    whole = np.floor(g)
    gps_ns = whole.astype(np.int64) * NS_PER_S + np.round((g - whole) * 1e9).astype(np.int64) + GPS_ORIGIN_NS
    return utc_ns_from_tai_ns(gps_ns - GPS_MINUS_TAI_NS).astype("datetime64[ns]")


def utc_to_gps_week(epoch_utc) -> tuple[np.ndarray, np.ndarray]:
    """(GPS week number int64, seconds of week float64) from UTC epochs."""
    s = utc_to_gps_seconds(epoch_utc)
    week = np.floor(s / 604800.0).astype(np.int64)
    return week, s - week * 604800.0
