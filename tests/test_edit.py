"""Editors against synthetic truth and the real GRAIL ODF outliers."""

import numpy as np
import pandas as pd
import pytest

from odpipe.preprocess import ambiguity
from odpipe.preprocess.edit import EditConfig, blunders, edit
from odpipe.preprocess.flags import Flag, names, summary
from odpipe.preprocess.robust import outliers
from parsers import table
from parsers.table import build
from parsers import odf, utdf

T0 = np.datetime64("2012-04-09T00:00:00", "ns")


def sine_doppler(n=7200, sigma=0.005, seed=0, **kw):
    """1-s Doppler of a lunar orbiter (30 kHz amplitude, 2-h period) plus white noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) + 0.5
    v = 3.0e4 * np.sin(2 * np.pi * t / 6800.0) + 0.02 * np.sin(2 * np.pi * t / 90.0) + rng.normal(0, sigma, n)
    cols = dict(epoch=T0 + (t * 1e9).astype("timedelta64[ns]"), tag="interval_mid", observable="doppler_1way",
                value=v, unit="Hz", count_time=1.0, station_rx="DSS-34", spacecraft="181", band_down="X",
                source="synthetic", record=np.arange(n), flags=0)
    cols.update(kw)
    return build(n, **cols)


def bits(table, flag):
    return (table["flags"].to_numpy() & int(flag)) != 0


def test_blunders_found_exactly_on_a_noisy_orbit_signal():
    tab = sine_doppler()
    hit = np.array([5, 700, 701, 3000, 7199])
    tab.loc[hit, "value"] += np.array([1e8, 0.5, 5.0, 2.0, -5e4])  # 100..1e10 sigma
    out, summ = edit(tab)
    assert np.array_equal(np.flatnonzero(bits(out, Flag.BLUNDER)), hit)
    assert len(out) == len(tab)
    assert summ.set_index("reason").loc["blunder", "rows"] == len(hit)


def test_slope_and_level_changes_are_not_blunders():
    """Ramped Doppler: the rate changes every few minutes and the level jumps once (a retuning)."""
    rng = np.random.default_rng(2)
    t = np.arange(3600) + 0.5
    rate = np.repeat(rng.uniform(-150.0, 150.0, 12), 300)           # Hz/s, 5-min ramp segments
    v = np.cumsum(rate) + 5e3 * (t > 1800.2) + rng.normal(0, 0.005, len(t))
    tab = sine_doppler(n=len(t))
    tab["value"] = v
    out, _ = edit(tab)
    assert not bits(out, Flag.BLUNDER).any()
    tab.loc[[905, 1805], "value"] += [3.0, -2.0]                      # 5 s after a rate change, after the jump
    out, _ = edit(tab)
    assert np.flatnonzero(bits(out, Flag.BLUNDER)).tolist() == [905, 1805]


def test_duplicates_invalid_elevation_short_pass_arc_and_windows():
    tab = sine_doppler(n=600)
    tab = pd.concat([tab, tab.iloc[[10]]], ignore_index=True)          # row 600 repeats row 10
    tab["validity"] = 0
    tab.loc[20, "validity"] = 1
    tab["elevation_rx"] = np.radians(np.linspace(5.0, 40.0, len(tab)))     # below 10 deg for the first rows
    late = sine_doppler(n=5, record=np.arange(1000, 1005), epoch=T0 + np.arange(5) * np.timedelta64(1, "s")
                        + np.timedelta64(2, "h"))
    late["validity"], late["elevation_rx"] = 0, 1.0
    tab = pd.concat([tab, late], ignore_index=True)
    cfg = EditConfig(arc=(T0, T0 + np.timedelta64(590, "s")),
                     windows=[{"start": T0 + np.timedelta64(300, "s"), "end": T0 + np.timedelta64(310, "s"),
                               "station_rx": "DSS-34"}])
    out, _ = edit(tab, config=cfg)
    assert np.flatnonzero(bits(out, Flag.DUPLICATE)).tolist() == [600]
    assert np.flatnonzero(bits(out, Flag.INVALID)).tolist() == [20]
    el = np.degrees(tab["elevation_rx"].to_numpy())
    assert np.array_equal(bits(out, Flag.ELEVATION), el < 10.0)
    assert np.flatnonzero(bits(out, Flag.SHORT_PASS)).tolist() == list(range(601, 606))
    assert bits(out, Flag.OUTSIDE_ARC).sum() == 10 + 5       # tags 590.5..599.5 s and the late pass
    assert np.flatnonzero(bits(out, Flag.USER)).tolist() == list(range(300, 310))
    assert names(out["flags"].iloc[601]) == ["short_pass", "outside_arc"]


def test_rows_the_elevation_mask_cannot_judge_are_logged(caplog):
    """No elevation_rx column, or NaN in it: the used rows the mask could not judge are counted in a warning."""
    tab = sine_doppler(n=600)
    with caplog.at_level("WARNING", logger="odpipe.preprocess.edit"):
        edit(tab)
    assert [r.getMessage() for r in caplog.records] == [
        "no elevation_rx column: the elevation mask was not applied to 600 used rows"]
    caplog.clear()
    tab["elevation_rx"] = np.radians(30.0)
    tab.loc[:99, "elevation_rx"] = np.nan                             # e.g. outside the trajectory
    with caplog.at_level("WARNING", logger="odpipe.preprocess.edit"):
        out, _ = edit(tab, config=EditConfig(arc=(T0 + np.timedelta64(50, "s"), T0 + np.timedelta64(600, "s"))))
    assert bits(out, Flag.OUTSIDE_ARC).sum() == 50                    # flagged anyway: not counted
    assert [r.getMessage() for r in caplog.records] == [
        "50 used rows have no elevation_rx (NaN): not checked against the elevation mask"]


def test_range_outside_its_modulus_is_flagged():
    tab = build(4, epoch=T0 + np.arange(4) * np.timedelta64(600, "s"), tag="receive", observable="range",
                value=[10.0, 2.0 ** 25, -1.0, 3.3e7], unit="RU", count_time=0.0, station_rx="DSS-25",
                source="synthetic", record=np.arange(4), flags=0, range_modulus_ru=2.0 ** 25)
    out, _ = edit(tab, config=EditConfig(min_pass_samples=1))
    assert bits(out, Flag.AMBIGUITY).tolist() == [False, True, True, False]


def test_ambiguity_resolution_recovers_the_true_range():
    rng = np.random.default_rng(4)
    modulus = 2.0 ** 25
    true = rng.uniform(1e8, 1e10, 1000)
    observed = np.mod(true, modulus)
    resolved, amb = ambiguity.resolve(observed, true + rng.normal(0, 1e5, 1000), modulus)
    assert not amb.any() and np.allclose(resolved, true, rtol=0, atol=1e-3)
    _, amb = ambiguity.resolve(observed, true + 0.45 * modulus, modulus)
    assert amb.all()


def test_residual_outliers_per_group():
    rng = np.random.default_rng(5)
    r = np.concatenate([rng.normal(0, 1.0, 500), rng.normal(0, 10.0, 500)])
    g = np.repeat([0, 1], 500)
    r[[3, 600]] = [20.0, 200.0]  # 20 sigma in each group; 20 would be normal in group 1
    assert np.flatnonzero(outliers(r, g, k=6.0)).tolist() == [3, 600]


def test_residual_outliers_flag_only_used_rows():
    from odpipe.preprocess.edit import residual_outliers

    rng = np.random.default_rng(7)
    tab = sine_doppler(n=1000)
    tab["pass_id"] = np.repeat([0, 1], 500)
    resid = rng.normal(0, 0.005, 1000)
    resid[[10, 700]] = 0.1               # 20 sigma
    tab.loc[20, "flags"] = int(Flag.BLUNDER)
    resid[20] = 1e3                      # already edited: not a residual outlier, not in the statistics
    tab.loc[30, "flags"] = int(Flag.RESIDUAL)
    resid[30] = 0.0                      # flagged by an earlier iteration, now fits: re-tested
    assert np.flatnonzero(residual_outliers(tab, resid, k=6.0)).tolist() == [10, 700]


def test_summary_counts_each_reason():
    s = summary([0, int(Flag.BLUNDER), int(Flag.BLUNDER | Flag.ELEVATION), 0]).set_index("reason")["rows"]
    assert s["blunder"] == 2 and s["elevation"] == 1 and s["used"] == 2 and s["duplicate"] == 0


# The 1-way (and one 2-way) GRAIL records flagged valid although |value| is 1e6..1.5e9 Hz.
GRAIL_OUTLIERS = {
    "grblugf2012_099_0620smmmv1.odf": [21121],
    "grblugf2012_100_0434smmmv1.odf": [9101, 9224, 16950, 44459, 50347],
    "grblugf2012_102_0055smmmv1.odf": [58401],
}


@pytest.mark.realdata
@pytest.mark.parametrize("name", sorted(GRAIL_OUTLIERS))
def test_grail_gross_outliers_are_flagged(shared_data, name):
    data = odf.read(shared_data / "grail" / name)
    tab = data.table
    big = tab.loc[tab["value"].abs() > 1e6, "record"].tolist()
    assert big == GRAIL_OUTLIERS[name]  # the file's text: these records are the 1e6..1e9 Hz values
    assert (tab["validity"] == 0).all()  # ... and the format calls them valid
    out, summ = edit(tab, data.ramps)
    assert len(out) == len(tab)
    blunder = out.loc[bits(out, Flag.BLUNDER), "record"]
    assert set(GRAIL_OUTLIERS[name]) <= set(blunder)
    # everything above 1e5 Hz is far outside any pass's Doppler and is caught too
    assert bits(out, Flag.BLUNDER)[tab["value"].abs().to_numpy() > 1e5].all()
    # editing is selective: under 1 % of the rows
    assert summ.set_index("reason").loc["blunder", "rows"] < 0.01 * len(tab)


@pytest.mark.realdata
def test_cassini_and_messenger_ramps_and_range_are_not_edited_as_blunders(shared_data):
    cas = odf.read(shared_data / "cassini" / "S18TIGM2006_058_0005X25MV1.ODF")
    out, _ = edit(cas.table, cas.ramps)
    blunder = bits(out, Flag.BLUNDER)
    # the 3-way passes sweep over 55 kHz while DSS-25's ramps arrive one light time later: not blunders
    assert blunder.sum() < 1e-3 * len(out)
    assert not blunder[out["observable"].to_numpy() == "range"].any()  # modulo 2^25 RU: left to the fit
    mes = odf.read(shared_data / "messenger" / "odf07155.odf")
    out, _ = edit(mes.table, mes.ramps)
    rng = out[out["observable"] == "range"]
    assert not (rng["flags"] != 0).any()                 # 30-min range points: passes, not short passes
    assert rng["pass_id"].nunique() < len(rng) / 5


@pytest.mark.realdata
def test_utdf_validity_bits_decide(shared_data):
    from odpipe.preprocess.edit import invalid

    path = shared_data / "utdf" / "LSUTDF_367501_119_2019_044_1555.trk"
    tab = utdf.read(path).table
    raw = np.frombuffer(path.read_bytes(), dtype=np.uint8).reshape(-1, 75)
    byte51 = raw[:, 50]  # data validity: bit 0 range, 1 Doppler, 2 angles (1-based byte 51)
    bad = invalid(tab)
    for obs, bit in (("range", 0), ("doppler_2way", 1), ("angle_az", 2), ("angle_el", 2)):
        rows = tab["observable"] == obs
        want = (byte51[tab.loc[rows, "record"].to_numpy()] >> bit) & 1 == 0
        assert np.array_equal(bad[rows.to_numpy()], want), obs
    assert bad.sum() == 633


def test_blunders_never_mix_observables_sharing_a_pass_id():
    # Doppler (Hz) and range (m) of one station numbered as one pass, as a simulator may do
    n = 120
    t = np.datetime64("2003-06-03T00:00", "ns") + np.arange(n) * np.timedelta64(60, "s")
    dop = table.build(n, epoch=t, observable="doppler_2way", value=1000.0 + 0.01 * np.arange(n), station_rx="DSS-14",
                      station_tx="DSS-14", count_time=60.0, pass_id=0)
    rng = table.build(12, epoch=t[::10], observable="range", value=2.9e8 + 3.7e5 * np.arange(12), station_rx="DSS-14",
                      station_tx="DSS-14", pass_id=0)
    tab = pd.concat([dop, rng], ignore_index=True)
    assert not blunders(tab).any()


def test_rows_without_a_usable_value_are_invalid():
    n = 4
    t = np.datetime64("2010-11-21T01:14", "ns") + np.arange(n) * np.timedelta64(10, "s")
    tab = table.build(n, epoch=t, observable="doppler_2way", value=[np.nan, 1.0, 2.0, 3.0],
                      count_time=[np.nan, 10.0, 10.0, np.nan], station_rx="PAD-11")
    from odpipe.preprocess.edit import invalid
    assert invalid(tab).tolist() == [True, False, False, True]
