"""TRK-2-34 link ends, Doppler mode and uplink band of downlink and derived SFDUs.

Rules checked (parsers.trk234.observables._link): the validated secondary-CHDO fields win
over the predicted ones, as Tudat's TNF loader (tudatpy data processing, getLinkEnds,
getTrackingMode, getRadioBand) reads them: uplink station ``vld_ul_stn`` else (2-way) the
receiver or (3-way) ``ul_prdx_stn``; mode ``vld_dop_mode`` else ``prdx_mode``, whose codes
are those of PyTrk234's SFDU.tracking_mode() (0 none, 1 1W, 2 2W, 3 3W, 4 invalid); uplink
band ``ul_band_dl`` (else ``ul_band``) with the PyTrk234 band codes (1 S, 2 X, 3 Ka). The
files are made by our writer; PyTrk234 (NASA-PDS/PyTrk234 @ 8d066cf, run outside CI on the
same bytes) decoded the six Doppler SFDUs with time stamps 2016-07-18 01:00:00..05,
tracking_mode() (from prdx_mode) 2W, 3W/24, 3W/24, Invalid, 3W/24, 2W, vld_dop_mode
0, 0, 2, 0, 3, 1, vld_ul_stn 0, 0, 0, 0, 54, 0 and ul_band_dl Unknown, X, X, S, S, S; and
the two downlink carrier phase SFDUs as 2W and 3W/63 with ul_band_dl X and Ka.
"""

from __future__ import annotations

import numpy as np
import pytest

from parsers import trk234

# (prdx_mode, vld_dop_mode, ul_prdx_stn, vld_ul_stn, ul_band, ul_band_dl) -> (observable, station_tx, band_up)
CASES = [
    ((2, 0, 0, 0, 1, 0), ("doppler_count_2way", "DSS-25", "S")),  # predicted 2-way: receiver transmits
    ((3, 0, 24, 0, 1, 2), ("doppler_count_3way", "DSS-24", "X")),  # predicted 3-way; band from ul_band_dl
    ((3, 2, 24, 0, 2, 2), ("doppler_count_2way", "DSS-25", "X")),  # validated 2-way overrides predicted 3-way
    ((4, 0, 0, 0, 1, 1), ("doppler_count_unknown", "", "")),  # invalid mode: no link claimed
    ((3, 3, 24, 54, 1, 1), ("doppler_count_3way", "DSS-54", "S")),  # validated uplink station wins
    ((2, 1, 0, 0, 1, 1), ("doppler_count_1way", "", "")),  # validated one-way: no transmitter, no uplink band
]


@pytest.fixture(scope="module")
def table(tmp_path_factory):
    n = len(CASES)
    fields = np.array([c[0] for c in CASES]).T
    b = trk234.new_block(6, n, year=2016, doy=200, sec=3600.0 + np.arange(n), scft_id=61, dl_dss_id=25,
                         prdx_mode=fields[0], vld_dop_mode=fields[1], ul_prdx_stn=fields[2], vld_ul_stn=fields[3],
                         ul_band=fields[4], ul_band_dl=fields[5], vld_dl_band=2, cnt_time=1.0,
                         dop_cnt=1e9 + np.arange(n))
    path = tmp_path_factory.mktemp("trk") / "links.tnf"
    trk234.write(path, [b])
    return trk234.read(path).table


def test_validated_fields_win_over_predicted(table):
    got = list(zip(table["observable"], table["station_tx"], table["band_up"]))
    assert got == [c[1] for c in CASES]
    assert set(table["station_rx"]) == {"DSS-25"} and set(table["band_down"]) == {"X"}
    stamps = np.datetime64("2016-07-18T01:00:00", "ns") + np.arange(6) * np.timedelta64(1, "s")
    assert (table["epoch"].to_numpy() == stamps).all()


def test_downlink_sfdu_takes_its_uplink_band_from_ul_band_dl(tmp_path):
    b = trk234.new_block(1, 2, year=2016, doy=200, sec=[10.0, 11.0], dl_dss_id=55, dl_band=2,
                         prdx_mode=[2, 3], ul_prdx_stn=[0, 63], ul_band_dl=[2, 3])
    trk234.write(tmp_path / "dl.tnf", [b])
    t = trk234.read(tmp_path / "dl.tnf").table
    assert list(t["station_tx"]) == ["DSS-55", "DSS-63"] and list(t["band_up"]) == ["X", "Ka"]
    assert list(t["band_down"]) == ["X", "X"]
