"""Solar and geomagnetic activity for the atmosphere models, from a space-weather file.

NRLMSISE-00 takes the previous day's F10.7, its 81-day centred mean and the daily Ap, or instead of
the daily Ap its Ap history (:meth:`ap_history`): the daily Ap, the 3-hourly Ap of the current UT
3-hour interval and of the three before it, and the means of the eight 3-hourly Ap 12-33 h and 36-57 h
before (the model's documented AP array). Two sources (the conventions of Orekit's readers of the same files):

* :class:`MonthlyForecast`, MSFC's MSAFE table of 13-month smoothed values: no day-to-day
  variation; values interpolated linearly in time between the month starts, the 81-day mean the
  value at the epoch, the previous day's flux the value one day earlier; its Ap history is seven
  copies of the Ap at the epoch (no 3-hourly values);
* :class:`DailyRecords`, CelesTrak's CSSI file: the observed F10.7 of the previous UTC day, the
  observed 81-day centred mean and the daily Ap of the epoch's UTC day.

:func:`open_space_weather` reads either, telling them apart by content.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from odpipe.time.scales import utc_to_tdb
from parsers.spaceweather import DailyIndices, SolarActivityTable, read_cssi, read_msafe

DAY = 86400.0


def _covered(path, epochs, t, nodes) -> None:
    if np.any(t < nodes[0]) or np.any(t > nodes[-1]):
        raise ValueError(f"{path}: covers {epochs[0]} to {epochs[-1]}, not the requested epochs")


@dataclass(frozen=True)
class MonthlyForecast:
    """Activity at TDB epochs (s past J2000) from a :class:`SolarActivityTable`."""

    table: SolarActivityTable

    def _interpolate(self, t, values):
        nodes = utc_to_tdb(self.table.epoch)
        _covered(self.table.path, self.table.epoch, t, nodes)
        return np.interp(t, nodes, values)

    def nrlmsise_inputs(self, t) -> np.ndarray:
        """(n, 3): F10.7 of the previous day, its 81-day mean, daily Ap at TDB epochs t."""
        t = np.atleast_1d(np.asarray(t, float))
        return np.column_stack([self._interpolate(t - DAY, self.table.f107), self._interpolate(t, self.table.f107),
                                self._interpolate(t, self.table.ap)])

    def ap_history(self, t) -> np.ndarray:
        """(n, 7): NRLMSISE-00's Ap history at TDB epochs t, every entry the Ap at t."""
        t = np.atleast_1d(np.asarray(t, float))
        return np.repeat(self._interpolate(t, self.table.ap)[:, None], 7, axis=1)


@dataclass(frozen=True)
class DailyRecords:
    """Activity at TDB epochs (s past J2000) from CSSI :class:`DailyIndices`."""

    table: DailyIndices

    def nrlmsise_inputs(self, t) -> np.ndarray:
        """(n, 3): observed F10.7 of the previous UTC day, observed 81-day mean and daily Ap of the day."""
        t = np.atleast_1d(np.asarray(t, float))
        nodes = utc_to_tdb(self.table.epoch)
        _covered(self.table.path, self.table.epoch, t - DAY, nodes)
        _covered(self.table.path, self.table.epoch, t, np.append(nodes, nodes[-1] + DAY))
        day = np.searchsorted(nodes, t, side="right") - 1
        return np.column_stack([self.table.f107[day - 1], self.table.f107_ctr81[day], self.table.ap[day]])

    def ap_history(self, t) -> np.ndarray:
        """(n, 7): NRLMSISE-00's Ap history at TDB epochs t: the day's Ap, the 3-hourly Ap of the
        UT interval holding t and of the three before, the means of the eight 12-33 h and 36-57 h before."""
        t = np.atleast_1d(np.asarray(t, float))
        nodes = utc_to_tdb(self.table.epoch)
        _covered(self.table.path, self.table.epoch, t - 57 * 3600.0, nodes)
        _covered(self.table.path, self.table.epoch, t, np.append(nodes, nodes[-1] + DAY))
        day = np.searchsorted(nodes, t, side="right") - 1
        j = 8 * day + np.floor((t - nodes[day]) / (DAY / 8)).astype(int)   # index of t's 3-hour interval
        a = self.table.ap_3h.ravel()
        back = a[j[:, None] - np.arange(20)]                                # its Ap and the 19 before
        return np.column_stack([self.table.ap[day], back[:, :4], back[:, 4:12].mean(1), back[:, 12:20].mean(1)])


def open_space_weather(path, level: str = "50%") -> MonthlyForecast | DailyRecords:
    """A CSSI file (it has a 'BEGIN OBSERVED' line) or else an MSAFE table read at ``level``."""
    with open(path, encoding="latin-1") as f:
        cssi = any(line.strip() == "BEGIN OBSERVED" for line in f)
    return DailyRecords(read_cssi(path)) if cssi else MonthlyForecast(read_msafe(path, level))
