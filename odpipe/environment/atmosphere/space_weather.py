"""Solar and geomagnetic activity for the atmosphere models, from a monthly forecast table.

NRLMSISE-00 takes the previous day's F10.7, its 81-day centred mean and the daily Ap. A
monthly table of 13-month smoothed values (MSFC's MSAFE) carries no day-to-day variation:
the values are interpolated linearly in time between the month starts, the 81-day mean is
the interpolated value at the epoch and the previous day's flux the value one day earlier
(the convention of Orekit's reader of the same files).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from odpipe.time.scales import utc_to_tdb
from parsers.spaceweather import SolarActivityTable

DAY = 86400.0


@dataclass(frozen=True)
class SpaceWeather:
    """Activity at TDB epochs (s past J2000) from a :class:`SolarActivityTable`."""

    table: SolarActivityTable

    def _interpolate(self, t, values):
        nodes = utc_to_tdb(self.table.epoch)
        t = np.asarray(t, float)
        if np.any(t < nodes[0]) or np.any(t > nodes[-1]):
            raise ValueError(f"{self.table.path}: covers {self.table.epoch[0]} to {self.table.epoch[-1]}, "
                             f"not the requested epochs")
        return np.interp(t, nodes, values)

    def nrlmsise_inputs(self, t) -> np.ndarray:
        """(n, 3): F10.7 of the previous day, its 81-day mean, daily Ap at TDB epochs t."""
        t = np.atleast_1d(np.asarray(t, float))
        return np.column_stack([self._interpolate(t - DAY, self.table.f107), self._interpolate(t, self.table.f107),
                                self._interpolate(t, self.table.ap)])
