"""TAI−UTC from the IERS leap-second file shipped by ``astropy-iers-data``.

The one reader of ``Leap_Second.dat`` (IERS Bulletin C history): the time scales
(``odpipe.time``) and the CCSDS TDM epochs (``parsers.tdm.times``) both use it;
nothing is typed in by hand. Only UTC since 1972-01-01 (integer leap seconds) is
supported: earlier "rubber-second" UTC raises ``ValueError``.
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np

import astropy_iers_data

from odpipe.constants import MJD_UNIX, NS_PER_DAY, NS_PER_S


def leap_second_file() -> Path:
    """Path of the IERS ``Leap_Second.dat`` file used for TAI−UTC."""
    return Path(astropy_iers_data.__file__).parent / "data" / "Leap_Second.dat"


@lru_cache(maxsize=1)
def leap_second_table() -> tuple[np.ndarray, np.ndarray]:
    """(UTC instants of each step as int64 ns since 1970, TAI−UTC in whole s after it)."""
    path = leap_second_file()
    rows = []
    for line in path.read_text().splitlines():
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        fields = line.split()
        rows.append((int(float(fields[0])), int(fields[4])))
    if not rows:
        raise ValueError(f"no leap-second rows in {path}")
    mjd = np.array([r[0] for r in rows], dtype=np.int64)
    dat = np.array([r[1] for r in rows], dtype=np.int64)
    return (mjd - MJD_UNIX) * NS_PER_DAY, dat


def _first_error(ns: np.ndarray, bad: np.ndarray, what: str) -> ValueError:
    first = np.asarray(ns)[bad].ravel()[0]
    return ValueError(f"{what} {np.datetime64(int(first), 'ns')} is before 1972-01-01 UTC; "
                      f"TAI-UTC is only tabulated for integer-second UTC ({leap_second_file().name})")


def tabulated(ns: np.ndarray, tai: bool = False) -> np.ndarray:
    """True where int64 ns since 1970 (UTC, or TAI if ``tai``) fall on or after 1972-01-01 UTC."""
    steps, dat = leap_second_table()
    return np.asarray(ns) >= steps[0] + (dat[0] * NS_PER_S if tai else 0)


def tai_minus_utc_ns(utc_ns: np.ndarray) -> np.ndarray:
    """TAI−UTC (int64 ns) at UTC instants given as int64 ns since 1970."""
    steps, dat = leap_second_table()
    idx = np.searchsorted(steps, utc_ns, side="right") - 1
    bad = idx < 0
    if np.any(bad):
        raise _first_error(utc_ns, bad, "UTC epoch")
    return dat[idx] * NS_PER_S


def utc_ns_from_tai_ns(tai_ns: np.ndarray) -> np.ndarray:
    """UTC (int64 ns since 1970) from TAI (int64 ns on the same calendar origin).

    datetime64 cannot hold second 60: a TAI instant inside an inserted leap
    second (23:59:60.x UTC) maps to 00:00:00 of the next UTC day, so the map
    stays monotonic and instants next to the leap second keep their ns.
    """
    steps, dat = leap_second_table()
    steps_tai = steps + dat * NS_PER_S
    idx = np.searchsorted(steps_tai, tai_ns, side="right") - 1
    bad = idx < 0
    if np.any(bad):
        raise _first_error(tai_ns, bad, "TAI epoch")
    next_step = np.append(steps[1:], np.iinfo(np.int64).max)[idx]
    return np.minimum(tai_ns - dat[idx] * NS_PER_S, next_step)
