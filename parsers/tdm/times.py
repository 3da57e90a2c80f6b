"""CCSDS epochs (YYYY-MM-DDThh:mm:ss[.f] or YYYY-DDDThh:mm:ss[.f], optional Z) <-> datetime64[ns].

TAI, GPS and TT epochs are turned into UTC with the IERS leap-second table
(``parsers.leap_seconds``); epochs before 1972 become NaT. Other time systems (TDB, TCB,
TCG, UT1, ...) are kept in their own scale: those rows' ``epoch`` is not UTC and their
``time_system`` column says so.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from odpipe.constants import GPS_MINUS_TAI_NS, NS_PER_S, TT_MINUS_TAI_NS
from parsers import leap_seconds

EPOCH = r"^\d{4}-(\d{2}-\d{2}|\d{3})T\d{2}:\d{2}:\d{2}(\.\d+)?$"

# Seconds to add to TAI to get each scale.
_FROM_TAI = {"TAI": 0.0, "GPS": GPS_MINUS_TAI_NS / NS_PER_S, "TT": TT_MINUS_TAI_NS / NS_PER_S}
LEAP_SCALES = set(_FROM_TAI)


def from_text(text: np.ndarray) -> np.ndarray:
    """datetime64[ns] of CCSDS epoch strings; NaT where a string is not an epoch."""
    s = pd.Series(np.asarray(text, dtype=object)).str.strip().str.rstrip("Z")
    shape = s.str.match(EPOCH).fillna(False).astype(bool)
    doy = s.str.match(r"^\d{4}-\d{3}T").fillna(False).astype(bool) & shape
    calendar = s.where(shape & ~doy)
    out = pd.to_datetime(calendar, format="ISO8601", errors="coerce").to_numpy("datetime64[ns]")
    if doy.any():
        d = s[doy]
        year = pd.to_numeric(d.str[:4], errors="coerce")
        day = pd.to_numeric(d.str[5:8], errors="coerce")
        clock = pd.to_timedelta(d.str[9:], errors="coerce")
        bad = (day < 1) | (day > 366) | clock.isna() | (clock >= pd.Timedelta(days=1))
        jan1 = pd.to_datetime(year.astype("Int64").astype(str) + "-01-01", errors="coerce")
        value = jan1 + pd.to_timedelta(day - 1, unit="D") + clock
        out[doy.to_numpy()] = np.where(bad, np.datetime64("NaT"), value.to_numpy("datetime64[ns]"))
    return out


def to_text(epochs: np.ndarray) -> np.ndarray:
    """CCSDS calendar strings of datetime64[ns] (milliseconds when that is exact, else ns)."""
    epochs = np.asarray(epochs, "datetime64[ns]")
    exact_ms = np.all(epochs.astype(np.int64) % 1_000_000 == 0)
    return np.datetime_as_string(epochs, unit="ms" if exact_ms else "ns")


def to_utc(epochs: np.ndarray, scale: str) -> np.ndarray:
    """UTC of epochs given in TAI, GPS or TT (others are returned unchanged)."""
    if scale not in LEAP_SCALES:
        return epochs
    tai = (epochs - np.timedelta64(int(round(_FROM_TAI[scale] * 1e9)), "ns")).astype(np.int64)
    ok = ~np.isnat(epochs) & leap_seconds.tabulated(tai, tai=True)
    out = np.full(tai.shape, np.datetime64("NaT"), "datetime64[ns]")
    out[ok] = leap_seconds.utc_ns_from_tai_ns(tai[ok]).astype("datetime64[ns]")
    return out


def from_utc(epochs: np.ndarray, scale: str) -> np.ndarray:
    """Epochs in ``scale`` (TAI, GPS or TT) of UTC epochs (others unchanged)."""
    if scale not in LEAP_SCALES:
        return epochs
    utc = np.asarray(epochs, "datetime64[ns]").astype(np.int64)
    ok = ~np.isnat(epochs) & leap_seconds.tabulated(utc)
    out = np.full(utc.shape, np.datetime64("NaT"), "datetime64[ns]")
    tai = utc[ok] + leap_seconds.tai_minus_utc_ns(utc[ok])
    out[ok] = (tai + int(round(_FROM_TAI[scale] * 1e9))).astype("datetime64[ns]")
    return out
