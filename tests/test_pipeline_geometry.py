"""add_geometry: rows sharing a station and time tag get the values computed once for that time, equal to
those of the rows alone; and the values against the topocentric direction computed from the target."""

import numpy as np

from odpipe.constants import C_LIGHT
from odpipe.environment.stations import StationCatalog, topocentric
from odpipe.pipeline.geometry import add_geometry
from odpipe.time import utc_to_tdb
from parsers import table as tt

T0 = np.datetime64("2012-04-10T04:00", "ns")
DIST = 3.8e8        # m: lunar distance, a fixed point in GCRS


class Fixed:
    """A 'trajectory' fixed in the GCRS about the Earth (state in m, m/s), spanning the day."""

    center = "earth"
    t0, t1 = float(utc_to_tdb(T0)) - 3600.0, float(utc_to_tdb(T0)) + 86400.0

    def state(self, t):
        t = np.atleast_1d(t)
        return np.tile([DIST * 0.6, DIST * 0.0, DIST * 0.8, 0.0, 0.0, 0.0], (t.size, 1))


def _table(n=30):
    ep = np.repeat(T0 + np.arange(n // 2) * np.timedelta64(600, "s"), 2)   # two rows per time tag
    return tt.build(n, epoch=ep, tag="interval_mid", value=0.0, unit="Hz", count_time=60.0,
                    observable=np.where(np.arange(n) % 2 == 0, "doppler_2way", "doppler_1way"),
                    station_tx="DSS-24", station_rx="DSS-24", spacecraft="181", band_up="S", band_down="S")


def test_rows_sharing_a_time_equal_the_rows_alone():
    catalog = StationCatalog.default()
    tab = _table()
    both = add_geometry(tab, Fixed(), None, catalog)
    alone = add_geometry(tab.iloc[::2].reset_index(drop=True), Fixed(), None, catalog)
    for col in ("elevation_rx", "azimuth_rx", "rtlt_s"):
        np.testing.assert_array_equal(both[col].to_numpy()[::2], alone[col].to_numpy())
        np.testing.assert_array_equal(both[col].to_numpy()[1::2], alone[col].to_numpy())


def test_direction_and_light_time_against_the_target_seen_from_the_station():
    """A target fixed in the GCRS at lunar distance: the light time moves nothing, so the elevation is the
    geometric one at the time tag and the round trip twice the station's range over c."""
    from odpipe.frames.earth import gcrs_to_itrs

    catalog = StationCatalog.default()
    tab = _table()
    out = add_geometry(tab, Fixed(), None, catalog)
    ep = tab["epoch"].to_numpy("datetime64[ns]")
    r_itrs = np.einsum("nij,j->ni", gcrs_to_itrs(ep), Fixed().state(0.0)[0, :3])
    az, el, rng = topocentric(catalog["DSS-24"], r_itrs, ep)
    np.testing.assert_allclose(out["elevation_rx"], el, rtol=0, atol=1e-12)
    np.testing.assert_allclose(out["azimuth_rx"], az, rtol=0, atol=1e-12)
    np.testing.assert_allclose(out["rtlt_s"], 2 * rng / C_LIGHT, rtol=0, atol=1e-12)
