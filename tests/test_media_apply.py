"""Applying media corrections to a TrackingTable: legs, times, signs, sources and smoothing."""

import numpy as np
import pytest

from odpipe.environment.stations import StationCatalog, itrs_to_geodetic, topocentric
from odpipe.constants import C_LIGHT
from odpipe.media.apply import calibrate
from odpipe.media.model import MediaModel
from odpipe.media.smoothing import smooth_by_group
from parsers import table as tt
from parsers.trk223 import read_trk223

DIST = 1.3e12          # m, a Saturn-like distance: round-trip light time ~2.4 h
T0 = np.datetime64("2006-02-27T00:00", "ns")


def target(t):
    """A far spacecraft fixed in inertial space, seen from Goldstone ~01:00-08:00 UTC on 2006-02-27."""
    s = (np.asarray(t, "datetime64[ns]") - T0) / np.timedelta64(1, "s")
    th = 2 * np.pi * s / 86164.0905 + 2.6
    ra, dec = 0.3 + 2 * np.pi * 5.3 / 23.934, 0.1
    return DIST * np.stack([np.cos(dec) * np.cos(ra - th), np.cos(dec) * np.sin(ra - th),
                            np.full_like(th, np.sin(dec))], -1)


def truth_range(t):
    s = (np.asarray(t, "datetime64[ns]") - T0) / np.timedelta64(1, "s")
    return 2.6e8 + 3.1e4 * s + 1e-3 * s ** 2


@pytest.fixture(scope="module")
def cal(shared_data):
    d = shared_data / "cassini"
    return read_trk223(d / "S18TIGE2006_032_2006_059.TRO", d / "S18TIGE2006_032_2006_059.ION")


def _table(n=40, start="2006-02-27T04:00"):
    ep = np.datetime64(start, "ns") + np.arange(n) * np.timedelta64(300, "s")
    return tt.build(n, epoch=ep, tag="interval_mid", value=0.0, unit="m", count_time=60.0,
                    observable=np.where(np.arange(n) % 2 == 0, "doppler_2way", "range"),
                    station_tx="DSS-25", station_rx="DSS-25", spacecraft="82", band_up="X", band_down="X",
                    uplink_hz=7.17e9, transponder_ratio=880 / 749)


def _leg(model, st, t, f, phase):
    """Troposphere + ionosphere delay (m) of one leg at DSS-25, computed directly from the models."""
    lat, lon, h = itrs_to_geodetic(st.r_itrs)
    az, el, _ = topocentric(st, target(t), t)
    trop, _ = model.troposphere("DSS-25", t, el, lat, h)
    lat_c = np.arctan2(st.r_itrs[2], np.hypot(st.r_itrs[0], st.r_itrs[1]))     # geocentric
    ion, _ = model.ionosphere("DSS-25", "82", t, el, az, lat_c, lon, np.full(t.shape, f))
    return trop + (-ion if phase else ion)


@pytest.mark.realdata
def test_round_trip_recovers_truth(cal):
    """Add known leg delays to synthetic range and Doppler, correct them, recover the truth."""
    model, st = MediaModel(cal), StationCatalog.default()["DSS-25"]
    tab = _table()
    out, report = calibrate(tab, model, target_itrs=target, order=None)
    ep = tab["epoch"].to_numpy().astype("datetime64[ns]")
    f_up, f_dn = 7.17e9, 7.17e9 * 880 / 749
    rtlt = lambda t: 2 * np.linalg.norm(target(t) - st.position_itrs(t), axis=-1) / C_LIGHT
    up_t = lambda t: t - (rtlt(t) * 1e9).round().astype("timedelta64[ns]")

    def path(t, phase):          # total path of a 2-way signal received at t
        return truth_range(t) + _leg(model, st, t, f_dn, phase) + _leg(model, st, up_t(t), f_up, phase)

    rng = out["observable"] == "range"
    observed = path(ep[rng], False)
    np.testing.assert_allclose(observed - out.loc[rng, "media_m"], truth_range(ep[rng]), rtol=0, atol=1e-6)
    dop = ~rng
    ts, te = ep[dop] - np.timedelta64(30, "s"), ep[dop] + np.timedelta64(30, "s")
    observed_rate = (path(te, True) - path(ts, True)) / 60.0           # count-averaged range rate
    truth_rate = (truth_range(te) - truth_range(ts)) / 60.0
    # 1e-7 m/s: float64 rounding of 1e9 m paths differenced over 60 s; media signals are ~1e-4 m/s
    np.testing.assert_allclose(observed_rate - out.loc[dop, "media_m"] / 60.0, truth_rate, rtol=0, atol=1e-7)
    # Doppler carries the change over the count, not the delay; the ionosphere flips sign (phase)
    assert out.loc[dop, "media_m"].abs().max() < 0.05 < out.loc[rng, "media_m"].min()
    assert (out.loc[rng, "iono_m"] > 0).all()
    # sources: TRO and ION cards of the files, per leg; RU from the X-band uplink, F = 221/1498
    assert out.loc[rng, "media_source"].str.contains(r"\.TRO:\d+ .*\| iono: S18TIGE2006_032_2006_059\.ION:314").all()
    assert out.loc[rng, "media_source_up"].str.contains(r"\.ION:314").all()
    np.testing.assert_allclose(out.loc[rng, "media_ru"], out.loc[rng, "media_m"] / C_LIGHT * 7.17e9 * 221 / 1498)
    assert (out["media_note"] == "").all() and len(report) == 2


@pytest.mark.realdata
def test_rows_not_asked_for_get_no_correction_and_the_others_the_same(cal):
    """A run corrects only the rows of its fitted observables: those keep the corrections of the
    round trip above (with per-pass smoothing, since passes never mix observables), the others none."""
    tab = _table(n=60)
    asked = (tab["observable"] == "doppler_2way").to_numpy()
    full, _ = calibrate(tab, MediaModel(cal), target_itrs=target)
    part, report = calibrate(tab, MediaModel(cal), target_itrs=target, rows=asked)
    for col in ("tropo_m", "iono_m", "media_m"):
        np.testing.assert_allclose(part.loc[asked, col], full.loc[asked, col], rtol=0, atol=1e-12)
        assert np.isnan(part.loc[~asked, col]).all() and np.isfinite(full.loc[~asked, col]).all()
    assert (part.loc[~asked, "media_note"] == "row not asked for: no correction").all()
    assert (part.loc[asked, "media_note"].astype(str) == full.loc[asked, "media_note"].astype(str)).all()
    assert (part.loc[~asked, "media_source"] == "").all()
    assert report.loc[report["observable"] == "range", "notes"].eq("row not asked for: no correction").all()


@pytest.mark.realdata
def test_pass_without_calibrations_is_flagged_with_fallback(cal):
    # 2007: outside every card -> DSN seasonal troposphere, no ionosphere; said per row and per pass
    tab = _table(n=10, start="2007-02-27T04:00")
    out, report = calibrate(tab, MediaModel(cal), target_itrs=target, order=None)
    assert out["media_source"].str.contains("DSN-seasonal \\(no TRO\\) \\| iono: none").all()
    for notes in report["notes"]:
        assert "no TRO coverage: DSN seasonal model used" in notes
        assert "no ionosphere calibration: none applied" in notes
    assert np.isfinite(out["tropo_m"]).all() and (out.loc[out.observable == "range", "iono_m"] == 0).all()


@pytest.mark.realdata
def test_elevation_columns_match_target_geometry(cal):
    st = StationCatalog.default()["DSS-25"]
    n = 60
    ep = np.datetime64("2006-02-27T03:00", "ns") + np.arange(n) * np.timedelta64(60, "s")
    az, el, _ = topocentric(st, target(ep), ep)
    tab = tt.build(n, epoch=ep, tag="interval_mid", observable="doppler_1way", value=0.0, unit="Hz",
                   count_time=10.0, station_rx="DSS-25", spacecraft="82", band_down="X", uplink_hz=8.4e9,
                   elevation_rx=el, azimuth_rx=az)
    a, _ = calibrate(tab, MediaModel(cal), target_itrs=target, order=None)
    b, _ = calibrate(tab, MediaModel(cal), order=None)
    inner = slice(1, -1)     # the first/last count intervals reach outside the tabulated elevations
    np.testing.assert_allclose(b["media_m"].to_numpy()[inner], a["media_m"].to_numpy()[inner], atol=2e-5)
    assert np.isnan(b["media_m"].iloc[0]) and "no spacecraft direction" in b["media_note"].iloc[0]


def test_smoothing_reproduces_polynomials_and_removes_noise():
    rng = np.random.default_rng(1)
    t = np.linspace(0, 8 * 3600, 400)
    x = t / t[-1]
    poly = 2.0 + 0.3 * x - 0.7 * x ** 3 + 0.2 * x ** 10
    group = np.repeat([0, 1], 200)
    out = smooth_by_group(t, np.where(group == 0, poly, poly + 1e-3 * rng.standard_normal(400)), group, 10)
    np.testing.assert_allclose(out[:200], poly[:200], atol=1e-10)
    assert np.std(out[200:] - poly[200:]) < 0.4e-3
    assert np.isnan(smooth_by_group(t[:3], np.array([1.0, np.nan, 2.0]), np.zeros(3), 10)[1])
