"""Epoch arguments of the frame functions: UTC datetime64 or TDB seconds past J2000."""

from __future__ import annotations

import numpy as np

from odpipe.constants import J2000_NS, NS_PER_DAY, SECONDS_PER_DAY, TT_MINUS_TAI_NS
from parsers.leap_seconds import tai_minus_utc_ns
from odpipe.time.scales import as_utc_ns, tdb_to_tt_seconds, tdb_to_utc


def utc_and_tt(t) -> tuple[np.ndarray, np.ndarray]:
    """(UTC int64 ns since 1970, TT days since J2000 TT float64) from either epoch kind.

    ``t`` is datetime64 (UTC) or float TDB seconds past J2000.
    """
    arr = np.asarray(t)
    if arr.dtype.kind in "MOUS":
        utc = as_utc_ns(arr)
        tt_ns = utc + tai_minus_utc_ns(utc) + TT_MINUS_TAI_NS - J2000_NS
        return utc, tt_ns / NS_PER_DAY
    if arr.dtype.kind not in "fiu":
        raise TypeError(f"epochs must be datetime64 UTC or float TDB seconds, got dtype {arr.dtype}")
    return as_utc_ns(tdb_to_utc(arr)), tdb_to_tt_seconds(arr) / SECONDS_PER_DAY
