"""Media calibration of the real Cassini ODF (2006-02-27) with its real TRK-2-23 files.

The spacecraft direction is Saturn's (Cassini orbits within ~1e-3 rad of it
as seen from Earth) from DE440, light-time corrected, rotated to ITRS.
"""

import numpy as np
import pytest

from odpipe.environment.ephemeris import Ephemeris
from odpipe.environment.stations import StationCatalog, topocentric
from odpipe.frames.earth import gcrs_to_itrs
from odpipe.constants import C_LIGHT
from odpipe.media.apply import calibrate
from odpipe.media.model import MediaModel
from odpipe.time.scales import utc_to_tdb
from parsers import odf
from parsers.ramps import RampStore
from parsers.trk223 import read_trk223

pytestmark = pytest.mark.realdata


@pytest.fixture(scope="module")
def saturn_itrs():
    eph = Ephemeris.open("de440")

    def target(t_utc):
        t_utc = np.atleast_1d(np.asarray(t_utc, "datetime64[ns]"))
        tdb = utc_to_tdb(t_utc)
        lt = np.linalg.norm(eph.position(6, 399, tdb), axis=-1) / C_LIGHT
        r = eph.position(6, 0, tdb - lt) - eph.position(399, 0, tdb)
        return np.einsum("nij,nj->ni", gcrs_to_itrs(t_utc), r)
    return target


def test_ion_card_windows_are_rise_to_set(shared_data, saturn_itrs):
    # TRK-2-23 (PDS MESSENGER ION product description): "The time span of the calibration is from
    # spacecraft rise (0 degrees) to set (0 degrees) at the receiving station or complex."
    cal = read_trk223(shared_data / "cassini" / "S18TIGE2006_032_2006_059.ION")
    cat = StationCatalog.default()
    checked = 0
    for card in cal.cards:
        if np.datetime64("2006-02-26") <= card.start < np.datetime64("2006-02-28"):
            st = cat[{"C10": "DSS-25", "C40": "DSS-34", "C60": "DSS-65"}[card.network]]
            t = np.array([card.start, card.end], dtype="datetime64[ns]")
            _, el, _ = topocentric(st, saturn_itrs(t), t)
            assert np.degrees(np.abs(el)).max() < 1.0, card.label
            checked += 1
    assert checked == 6


def test_calibrate_cassini_odf(shared_data, saturn_itrs):
    d = shared_data / "cassini"
    data = odf.read(d / "S18TIGM2006_058_0005X25MV1.ODF")
    table = data.table
    table = table[(table["observable"] == "range") | (np.arange(len(table)) % 50 == 0)].reset_index(drop=True)
    cal = read_trk223(d / "S18TIGE2006_032_2006_059.TRO", d / "S18TIGE2006_032_2006_059.ION")
    out, report = calibrate(table, MediaModel(cal), target_itrs=saturn_itrs, ramps=data.ramps, order=None)
    two_way = out[out["observable"] != "doppler_3way"]
    assert np.isfinite(two_way["media_m"]).all()
    assert two_way["media_source"].str.contains(r"\.TRO:\d+ .*\| iono: .*\.ION:\d+").all()

    # one range row by hand: ION card lines 314-316 (C10, 06/02/26 22:59 .. 06/02/27 12:52), S-band metres
    # scaled by (2295 MHz / f)^2 on each leg; the uplink leg one round-trip light time earlier
    c = [0.5925, 0.1149, 0.5121, -1.4846, 2.8097, 4.1571, -2.3807, -8.3126, 0.6299, 4.8878]
    t0, t1 = np.datetime64("2006-02-26T22:59", "ns"), np.datetime64("2006-02-27T12:52", "ns")

    def card(t):
        x = 2 * ((t - t0) / (t1 - t0)) - 1
        return sum(ci * x ** i for i, ci in enumerate(c))
    row = out[out["observable"] == "range"].iloc[10]
    t_rx = np.datetime64(row["epoch"], "ns")
    st = StationCatalog.default()["DSS-25"]
    rtlt = 2 * np.linalg.norm(saturn_itrs(t_rx) - st.position_itrs(t_rx[None]), axis=-1)[0] / C_LIGHT
    t_tx = t_rx - np.timedelta64(int(round(rtlt * 1e9)), "ns")
    f_up = RampStore(data.ramps).frequency("DSS-25", t_tx[None])[0]   # ramped uplink at transmission
    assert 7.1e9 < f_up < 7.2e9
    expected = card(t_rx) * (2295e6 / (f_up * 880 / 749)) ** 2 + card(t_tx) * (2295e6 / f_up) ** 2
    assert row["iono_m"] == pytest.approx(expected, rel=1e-9)
    # range units: F = 221/(749*2) for an X-band uplink (Moyer ch. 13) times the uplink at transmission
    assert row["media_ru"] == pytest.approx(row["media_m"] / C_LIGHT * f_up * 221 / 1498, rel=1e-9)
    # Saturn from Goldstone, both legs above ~10 deg: a few metres of troposphere per leg
    assert 4.0 < row["tropo_m"] < 30.0
    assert len(report) == out["pass_id"].nunique()
