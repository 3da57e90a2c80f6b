"""Reader of NASA MSFC's solar-activity forecast tables (MSAFE, e.g. ``Oct2010F10.txt``).

The table (after its title lines) has one row per month::

     2010.8337   NOV   109.0      92.6      78.2       7.6       5.6       3.6

decimal year of the month, month abbreviation, the 13-month smoothed F10.7 solar flux
(1e-22 W m^-2 Hz^-1) at the 95 %, 50 % and 5 % percentiles, then the geomagnetic index Ap at
the same three percentiles. A row dates the first day of its month, 00:00 UTC (its decimal
year must agree within half a month). Lines that are not rows (titles, headers, blank) are
skipped; a line that starts with a decimal year but is not a valid row is an error.
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
