"""Readers of space-weather tables: NASA MSFC's monthly forecasts (MSAFE) and CelesTrak's CSSI daily file.

**MSAFE** (e.g. ``Oct2010F10.txt``): the table (after its title lines) has one row per month::

     2010.8337   NOV   109.0      92.6      78.2       7.6       5.6       3.6

decimal year of the month, month abbreviation, the 13-month smoothed F10.7 solar flux
(1e-22 W m^-2 Hz^-1) at the 95 %, 50 % and 5 % percentiles, then the geomagnetic index Ap at
the same three percentiles. A row dates the first day of its month, 00:00 UTC (its decimal
year must agree within half a month). Lines that are not rows (titles, headers, blank) are
skipped; a line that starts with a decimal year but is not a valid row is an error.

**CSSI** (``SW-All.txt``, ``SpaceWeather-All-v1.2.txt``): one day per line in the sections
``BEGIN OBSERVED`` and ``BEGIN DAILY_PREDICTED`` (monthly predictions are not read), in the
columns of FORMAT(I4,I3,I3,I5,I3,8I3,I4,8I4,I4,F4.1,I2,I4,F6.1,I2,5F6.1): year, month, day, ...,
eight 3-hourly Ap (columns 47-78), daily Ap (79-82), ..., observed F10.7 (113-118) and its
81-day centred mean (119-124). Days must follow each other one day apart.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from parsers.errors import ParseError
from parsers.fields import Fields, numbered_lines

LEVELS = ("95%", "50%", "5%")  # percentile columns, in the file's order
MONTHS = ("JAN", "FEB", "MAR", "APR", "MAY", "JUN", "JUL", "AUG", "SEP", "OCT", "NOV", "DEC")
_ROW = re.compile(r"\s*\d{4}\.\d+\s")


@dataclass(frozen=True)
class DailyIndices:
    """CSSI daily records: ``epoch`` datetime64[ns] UTC (day starts), observed F10.7, its 81-day
    centred mean, daily Ap, the eight 3-hourly Ap (n, 8)."""

    path: str
    epoch: np.ndarray
    f107: np.ndarray
    f107_ctr81: np.ndarray
    ap: np.ndarray
    ap_3h: np.ndarray


# CSSI columns (0-based slices) read: name -> (start, end)
CSSI_COLUMNS = {"year": (0, 4), "month": (4, 7), "day": (7, 10), "ap_3h": (46, 78), "ap": (78, 82),
                "f107": (112, 118), "f107_ctr81": (118, 124)}
_SECTIONS = ("BEGIN OBSERVED", "BEGIN DAILY_PREDICTED")


def read_cssi(path) -> DailyIndices:
    """Read the observed and daily-predicted records of a CSSI space-weather file."""
    path = Path(path)
    inside, epochs, rows = False, [], []
    for number, text in numbered_lines(path):
        word = text.strip()
        if word.startswith(("BEGIN ", "END ")):
            inside = word in _SECTIONS
            continue
        if not inside or not word:
            continue
        f = Fields(path, number, text, fields=[text[a:b].strip() for a, b in CSSI_COLUMNS.values()], fixed=True)
        if len(text.rstrip()) < CSSI_COLUMNS["f107_ctr81"][1]:
            raise f.error(f"expected {CSSI_COLUMNS['f107_ctr81'][1]} columns (up to the observed 81-day F10.7), "
                          f"found {len(text.rstrip())}")
        try:
            epoch = np.datetime64(f"{f.int(0, 'year'):04d}-{f.int(1, 'month'):02d}-{f.int(2, 'day'):02d}", "ns")
        except ValueError:
            raise f.error(f"no such date: {text[:10].strip()!r}") from None
        if epochs and epoch != epochs[-1] + np.timedelta64(1, "D"):
            raise f.error(f"{str(epoch)[:10]} does not follow {str(epochs[-1])[:10]} by one day")
        ap_3h = Fields(path, number, text, fields=text[46:78].split(), fixed=True)
        if len(ap_3h) != 8:
            raise f.error(f"columns 47-78 must hold eight 3-hourly Ap, found {len(ap_3h)}")
        rows.append([f.float(5, "observed F10.7"), f.float(6, "observed F10.7 81-day mean"), f.float(4, "daily Ap")]
                    + [ap_3h.float(k, "3-hourly Ap") for k in range(8)])
        epochs.append(epoch)
    if not epochs:
        raise ParseError(path, "no daily record in a BEGIN OBSERVED or BEGIN DAILY_PREDICTED section")
    a = np.array(rows)
    return DailyIndices(str(path), np.array(epochs, "datetime64[ns]"), a[:, 0], a[:, 1], a[:, 2], a[:, 3:])


@dataclass(frozen=True)
class SolarActivityTable:
    """Monthly F10.7 and Ap at one percentile ``level``: ``epoch`` datetime64[ns] UTC (month starts)."""

    path: str
    level: str
    epoch: np.ndarray
    f107: np.ndarray
    ap: np.ndarray


def read_msafe(path, level: str = "50%") -> SolarActivityTable:
    """Read an MSAFE table keeping the ``level`` percentile columns ('95%', '50%' or '5%')."""
    if level not in LEVELS:
        raise ValueError(f"solar activity level must be one of {', '.join(LEVELS)}, not {level!r}")
    col = LEVELS.index(level)
    path = Path(path)
    epochs, f107, ap = [], [], []
    for number, text in numbered_lines(path):
        if not _ROW.match(text):
            continue
        f = Fields(path, number, text)
        f.need(8, "decimal year, month, F10.7 at 95/50/5 %, Ap at 95/50/5 %")
        year = f.float(0, "decimal year")
        month = f.str(1).upper()
        if month not in MONTHS:
            raise f.error(f"field 2 (month) must be one of JAN..DEC, not {f.str(1)!r}")
        m = MONTHS.index(month)
        if abs(year - (int(year) + m / 12.0)) > 1.0 / 24.0:
            raise f.error(f"decimal year {f.str(0)} is not in {month} of {int(year)}")
        epoch = np.datetime64(f"{int(year):04d}-{m + 1:02d}-01T00:00:00", "ns")
        if epochs and epoch <= epochs[-1]:
            raise f.error(f"{month} {int(year)} does not follow the previous row's month")
        flux, index = f.float(2 + col, f"F10.7 {level}"), f.float(5 + col, f"Ap {level}")
        if flux <= 0.0 or index < 0.0:
            raise f.error(f"F10.7 must be positive and Ap not negative, found {flux} and {index}")
        epochs.append(epoch)
        f107.append(flux)
        ap.append(index)
    if len(epochs) < 2:
        raise ParseError(path, f"expected at least two monthly rows (decimal year, month, F10.7, Ap), "
                               f"found {len(epochs)}")
    return SolarActivityTable(str(path), level, np.array(epochs, "datetime64[ns]"), np.array(f107), np.array(ap))
