"""Station displacements added to catalogue positions: solid Earth tide and ocean loading.

``StationDisplacement(solid_tides, ocean_loading)`` gives, for a :class:`~.stations.Station`
at TDB epochs, its catalogue position (with plate motion) plus the solid Earth tide
(:mod:`.solid_tides`, IERS 2010 §7.1.1, decimetres) and the ocean loading of its BLQ
site (:mod:`.ocean_loading`, §7.1.2, millimetres to centimetres). A BLQ site belongs to
a station whose name equals the site name or the part before its '/' (e.g. 'SHLD/C1'
for 'SHLD'); the first such site in the file is used. The measurement models take it
through ``MeasurementSetup.station_displacement``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from odpipe.environment.ocean_loading import ocean_loading_displacement
from odpipe.environment.solid_tides import station_tide_displacement
from odpipe.time.scales import tdb_to_utc


def sites_by_station(blq_sites: dict) -> dict:
    """BLQ sites keyed by the station name they apply to (site name and the part before '/')."""
    out = {}
    for name, site in blq_sites.items():
        for key in (name.split("/")[0], name):
            out.setdefault(key.upper(), site)
    return out


@dataclass(frozen=True)
class StationDisplacement:
    """Which displacements to add: the solid tide (bool) and BLQ ocean-loading sites by station name."""

    solid_tides: bool = False
    ocean_loading: dict = field(default_factory=dict)

    def displacement(self, station, t_tdb, ephemeris, gcrs_to_itrs) -> np.ndarray:
        """ITRS displacement (N,3) m of ``station`` at TDB s ``t_tdb`` (N,)."""
        t = np.atleast_1d(np.asarray(t_tdb, dtype=float))
        r = np.broadcast_to(station.position_itrs(t), (t.size, 3))
        out = np.zeros((t.size, 3))
        site = self.ocean_loading.get(station.name.upper())
        if not (self.solid_tides or site):
            return out
        if self.solid_tides:
            out += station_tide_displacement(r, t, ephemeris, gcrs_to_itrs)
        if site is not None:
            out += ocean_loading_displacement(site, r, tdb_to_utc(t))
        return out

    def position(self, station, t_tdb, ephemeris, gcrs_to_itrs) -> np.ndarray:
        """ITRS position (N,3) m: catalogue position with plate motion plus :meth:`displacement`."""
        t = np.atleast_1d(np.asarray(t_tdb, dtype=float))
        return station.position_itrs(t) + self.displacement(station, t, ephemeris, gcrs_to_itrs)
