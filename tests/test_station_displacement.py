"""Station displacements reach the measurement models: a range moves by the displacement along the line of sight."""

from pathlib import Path

import numpy as np

from odpipe.environment.ocean_loading import ocean_loading_displacement
from odpipe.environment.station_displacement import StationDisplacement, sites_by_station
from odpipe.environment.stations import Station, geodetic_to_itrs
from odpipe.measurements import MeasurementSetup, compute
from odpipe.time import utc_to_tdb
from parsers import blq
from parsers.table import build

GNSS_BLQ = Path("orekit_od/february-2016/gnss.blq")  # below the shared data folder
EPOCHS = np.datetime64("2016-02-13T00:00:00", "ns") + np.arange(0, 86400, 1800) * np.timedelta64(1, "s")


class FixedPoint:
    """A 'trajectory' resting at a GCRS position (m): the geometry is then known without an orbit."""

    center = "earth"

    def __init__(self, r):
        self.r = np.asarray(r, float)

    def state(self, t):
        t = np.atleast_1d(t)
        return np.tile(np.r_[self.r, 0.0, 0.0, 0.0], (t.size, 1))


def _ranges(setup, target):
    rows = build(EPOCHS.size, epoch=EPOCHS, observable="range", unit="m", station_tx="DSS-14", station_rx="DSS-14",
                 spacecraft="SC", tag="receive", count_time=0.0, band_up="X", band_down="X", uplink_hz=7.16e9,
                 ramped=False, pass_id=0, flags=0, value=0.0)
    return compute(rows, {"SC": target}, setup).value


def test_range_moves_by_solid_tide_along_line_of_sight():
    base = MeasurementSetup.default()
    tides = StationDisplacement(solid_tides=True)
    target = FixedPoint([12_000e3, -25_000e3, 9_000e3])
    dr = _ranges(MeasurementSetup.default(station_displacement=tides), target) - _ranges(base, target)

    t = utc_to_tdb(EPOCHS)
    st = base.stations["DSS-14"]
    d = tides.displacement(st, t, base.ephemeris, base.gcrs_to_itrs)
    los = np.einsum("nij,j->ni", base.gcrs_to_itrs(t), target.r) - st.position_itrs(t)
    expected = -np.einsum("ni,ni->n", d, los / np.linalg.norm(los, axis=1)[:, None])
    assert np.ptp(expected) > 0.1                       # decimetres of tide along the line of sight
    np.testing.assert_allclose(dr, expected, rtol=0, atol=1e-4)  # light time: < 1e-5 m of LOS/epoch change


def test_ocean_loading_sites_found_by_station_name(shared_data):
    sites = blq.read(shared_data / GNSS_BLQ)
    by_station = sites_by_station(sites)
    assert by_station["SHLD"] is sites["SHLD/C1"] and by_station["SBCH/P2"] is sites["SBCH/P2"]
    lat, lon = np.radians(41.8684), np.radians(240.9843)
    shld = Station("SHLD", geodetic_to_itrs(lat, lon, 0.0), epoch_year=2016.0)
    t = utc_to_tdb(EPOCHS)
    base = MeasurementSetup.default()
    both = StationDisplacement(True, by_station).displacement(shld, t, base.ephemeris, base.gcrs_to_itrs)
    tide = StationDisplacement(True).displacement(shld, t, base.ephemeris, base.gcrs_to_itrs)
    ocean = ocean_loading_displacement(sites["SHLD/C1"], shld.position_itrs(t), EPOCHS)
    np.testing.assert_allclose(both - tide, ocean, rtol=0, atol=1e-9)
    assert 0.005 < np.abs(ocean).max() < 0.03           # SHLD's K1 + M2 loading: about a centimetre
    assert not StationDisplacement(False, by_station).displacement(
        Station("7090", shld.r_itrs), t, base.ephemeris, base.gcrs_to_itrs).any()


def test_config_keys_build_the_displacement(shared_data):
    from odpipe.pipeline.config import MeasurementsSection
    from odpipe.pipeline.setup import station_displacement

    assert station_displacement(MeasurementsSection()) is None
    d = station_displacement(MeasurementsSection(station_tides=True, ocean_loading=shared_data / GNSS_BLQ))
    assert d.solid_tides and d.ocean_loading["SHLD"].name == "SHLD/C1" and len(d.ocean_loading) == 20
