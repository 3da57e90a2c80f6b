"""Doppler compression against analytic truth: exact averages, sqrt(N) noise, and edge cases."""

import numpy as np
import pandas as pd
import pytest

from odpipe.preprocess.compress import compress
from odpipe.preprocess.flags import Flag
from parsers.table import build, empty_ramps
from parsers import odf

T0 = np.datetime64("2012-04-09T00:00:00", "ns")
A, B, C, W = 2.1e6, -3.5, 40.0, 2 * np.pi / 7000.0  # Hz, Hz/s, Hz, rad/s


def truth_integral(t):
    """Antiderivative (cycles) of the true Doppler f(t) = A + B t + C sin(W t), t in s."""
    return A * t + 0.5 * B * t * t - C / W * np.cos(W * t)


def doppler_table(t_mid, count=1.0, noise=None, tag="interval_mid", **kw):
    """1-s count-averaged Doppler, values the exact mean of f over each count interval."""
    t_mid = np.asarray(t_mid, dtype=float)
    v = (truth_integral(t_mid + count / 2) - truth_integral(t_mid - count / 2)) / count
    if noise is not None:
        v = v + noise
    shift = {"interval_mid": 0.0, "interval_end": count / 2, "interval_start": -count / 2}[tag]
    epoch = T0 + np.rint((t_mid + shift) * 1e9).astype("timedelta64[ns]")
    cols = dict(epoch=epoch, tag=tag, observable="doppler_2way", value=v, unit="Hz", sigma=0.01,
                count_time=count, station_tx="DSS-24", station_rx="DSS-24", spacecraft="181",
                band_up="S", band_down="S", ramped=False, uplink_hz=2.1e9, source="synthetic",
                record=np.arange(len(t_mid)), flags=0)
    cols.update(kw)
    return build(len(t_mid), **cols)


def window_truth(out):
    """Exact mean of f over each output row's interval (mid-tagged rows)."""
    mid = (out["epoch"] - T0).dt.total_seconds().to_numpy()
    ct = out["count_time"].to_numpy()
    return (truth_integral(mid + ct / 2) - truth_integral(mid - ct / 2)) / ct


def test_compression_reproduces_the_exact_average_over_the_new_count():
    tab = doppler_table(np.arange(0.5, 3600.0, 1.0))  # intervals [0,1), [1,2), ... back to back
    out, rep = compress(tab, 60.0)
    assert len(out) == 60 and rep.averaged_rows == 60 and rep.partial_rows == 0
    assert np.allclose(out["count_time"], 60.0)
    assert np.all(out["n_samples"] == 60)
    # first window spans [0, 60) s: mid tag at 30 s
    assert out["epoch"].iloc[0] == T0 + np.timedelta64(30, "s")
    err = out["value"].to_numpy() - window_truth(out)
    assert np.max(np.abs(err)) < 1e-7  # Hz, on values of 2e6 Hz


@pytest.mark.parametrize("tag,offset_s", [("interval_end", 60.0), ("interval_start", 0.0)])
def test_time_tag_convention_is_kept(tag, offset_s):
    tab = doppler_table(np.arange(0.5, 600.0, 1.0), tag=tag)
    out, _ = compress(tab, 60.0)
    assert (out["tag"] == tag).all()
    assert out["epoch"].iloc[0] == T0 + np.timedelta64(int(offset_s), "s")
    mid = (out["epoch"] - T0).dt.total_seconds().to_numpy() + {"interval_end": -30, "interval_start": 30}[tag]
    exact = (truth_integral(mid + 30) - truth_integral(mid - 30)) / 60
    assert np.max(np.abs(out["value"].to_numpy() - exact)) < 1e-7


def test_white_noise_scatter_falls_by_sqrt_n():
    rng = np.random.default_rng(1)
    n = 60 * 2000
    sigma = 0.05
    noise = rng.normal(0.0, sigma, n)
    tab = doppler_table(np.arange(n) + 0.5, noise=noise)
    out, _ = compress(tab, 60.0)
    resid = out["value"].to_numpy() - window_truth(out)
    ratio = np.std(tab["value"].to_numpy() - doppler_table(np.arange(n) + 0.5)["value"].to_numpy()) / np.std(resid)
    assert ratio == pytest.approx(np.sqrt(60), rel=0.05)
    # the new sigma, estimated from each window's scatter, matches sigma/sqrt(60) on average
    assert np.median(out["sigma"]) == pytest.approx(sigma / np.sqrt(60), rel=0.05)
    assert np.median(out["scatter"]) == pytest.approx(sigma, rel=0.05)


def test_gap_inside_a_window_splits_it():
    t = np.arange(0.5, 300.0, 1.0)
    t = t[(t < 100) | (t > 105)]  # intervals [100, 105) missing, inside the window [60, 120)
    out, rep = compress(doppler_table(t), 60.0, partial="keep")
    # every compressed row is one contiguous run: its count time equals its sample count
    assert np.allclose(out["count_time"], out["n_samples"] * 1.0)
    assert out["n_samples"].sum() == len(t)
    assert np.max(np.abs(out["value"].to_numpy() - window_truth(out))) < 1e-7
    # the run before the hole ends at 100 s, the one after starts at 105 s
    starts = (out["epoch"] - T0).dt.total_seconds() - out["count_time"] / 2
    ends = starts + out["count_time"]
    assert 100.0 in set(np.round(ends, 6)) and 105.0 in set(np.round(starts, 6))
    assert not ((starts < 100) & (ends > 100)).any()


def test_ramp_change_is_never_crossed():
    t = np.arange(0.5, 600.0, 1.0)
    tab = doppler_table(t, ramped=True, uplink_hz=np.nan)
    ramps = pd.concat([empty_ramps(), pd.DataFrame({
        "station": ["DSS-24", "DSS-24"], "start": [T0, T0 + np.timedelta64(90, "s")], "end": [pd.NaT, pd.NaT],
        "freq_hz": [2.1e9, 2.1e9 + 90 * 5.0], "rate_hz_s": [5.0, -2.0], "band": "S",
        "source": "synthetic", "record": [0, 1]})], ignore_index=True)
    out, _ = compress(tab, 60.0, ramps=ramps)
    starts = (out["epoch"] - T0).dt.total_seconds() - out["count_time"] / 2
    ends = starts + out["count_time"]
    assert not ((starts < 90) & (ends > 90)).any()
    assert 90.0 in set(np.round(ends, 6)) and 90.0 in set(np.round(starts, 6))
    # a continuous ramp (rate change only) does not split the pass
    assert out["pass_id"].nunique() == 1
    # the change reaches the data one round-trip light time later
    late, _ = compress(tab, 60.0, ramps=ramps, ramp_delay=2.5)
    starts = (late["epoch"] - T0).dt.total_seconds() - late["count_time"] / 2
    assert 93.0 in set(np.round(starts, 6)) and 90.0 not in set(np.round(starts, 6))


@pytest.mark.parametrize("partial", ["keep", "flag", "drop"])
def test_pass_shorter_than_the_count_time(partial):
    out, rep = compress(doppler_table(np.arange(0.5, 20.0, 1.0)), 60.0, partial=partial)
    assert rep.partial_rows == 1
    if partial == "drop":
        assert len(out) == 0
        assert sorted(rep.dropped["record"]) == list(range(20))
        return
    assert len(out) == 1 and out["count_time"].iloc[0] == 20.0 and out["n_samples"].iloc[0] == 20
    assert (out["flags"].iloc[0] & Flag.PARTIAL_COUNT) == (Flag.PARTIAL_COUNT if partial == "flag" else 0)
    assert out["value"].iloc[0] == pytest.approx(window_truth(out)[0], abs=1e-7)


def test_unsorted_input_gives_the_same_result():
    tab = doppler_table(np.arange(0.5, 1800.0, 1.0))
    shuffled = tab.sample(frac=1.0, random_state=3).reset_index(drop=True)
    a, _ = compress(tab, 60.0)
    b, _ = compress(shuffled, 60.0)
    assert np.array_equal(a["value"].to_numpy(), b["value"].to_numpy())
    assert [list(r) for r in a["source_records"]] == [list(r) for r in b["source_records"]]


def test_flagged_rows_pass_through_and_break_contiguity():
    tab = doppler_table(np.arange(0.5, 120.0, 1.0))
    tab.loc[30, "flags"] = int(Flag.BLUNDER)
    tab.loc[30, "value"] = 1e8
    out, rep = compress(tab, 60.0)
    assert rep.passthrough_rows == 1
    flagged = out[out["flags"] != 0]
    assert len(flagged) == 1 and flagged["value"].iloc[0] == 1e8
    good = out[out["flags"] == 0]
    assert np.max(np.abs(good["value"].to_numpy() - window_truth(good))) < 1e-7
    assert out["n_samples"].sum() == len(tab)


@pytest.mark.parametrize("observable", ["phase_downlink", "total_phase"])
def test_accumulated_phase_is_differenced_exactly(observable):
    t = np.arange(0.0, 601.0, 1.0)  # 601 phase samples span 600 s
    phase = truth_integral(t) - truth_integral(0.0)
    tab = build(len(t), epoch=T0 + (t * 1e9).astype("timedelta64[ns]"), tag="receive",
                observable=observable, value=phase, unit="cycles", sigma=1e-3, count_time=0.0,
                station_rx="DSS-24", spacecraft="181", band_down="X", source="synthetic",
                record=np.arange(len(t)), flags=0)
    out, rep = compress(tab, 60.0)
    assert rep.phase_rows == 10 and len(rep.dropped) == 0
    assert (out["observable"] == observable + "_rate").all() and (out["unit"] == "Hz").all()
    assert np.allclose(out["count_time"], 60.0)
    assert np.max(np.abs(out["value"].to_numpy() - window_truth(out))) < 1e-6
    assert list(out["source_records"].iloc[1]) == list(range(60, 121))


def test_phase_is_never_differenced_across_a_hole():
    t = np.arange(0.0, 301.0, 1.0)
    t = t[(t < 100) | (t > 130)]                                    # 31-s hole: lock may have been lost
    tab = build(len(t), epoch=T0 + (t * 1e9).astype("timedelta64[ns]"), tag="receive",
                observable="total_phase", value=truth_integral(t), unit="cycles", count_time=0.0,
                station_rx="DSS-24", source="synthetic", record=np.arange(len(t)), flags=0)
    out, rep = compress(tab, 60.0)
    start = (out["epoch"] - T0).dt.total_seconds() - out["count_time"] / 2
    end = start + out["count_time"]
    assert not ((start < 100) & (end > 130)).any()
    assert 99.0 in set(np.round(end, 6)) and 131.0 in set(np.round(start, 6))
    assert np.max(np.abs(out["value"].to_numpy() - window_truth(out))) < 1e-6


def test_format_columns_of_compressed_rows():
    tab = doppler_table(np.arange(0.5, 120.0, 1.0))
    tab["elevation_rx"] = np.linspace(0.1, 0.2, len(tab))            # float: averaged over the window
    tab["item21"] = 100                                             # constant code: kept
    tab["observable_int"] = np.arange(len(tab))                     # varies: no longer meaningful
    out, _ = compress(tab, 60.0)
    assert np.allclose(out["elevation_rx"], [tab["elevation_rx"][:60].mean(), tab["elevation_rx"][60:].mean()])
    assert list(out["item21"]) == [100, 100] and list(out["observable_int"]) == [-1, -1]


def test_doppler_counts_in_cycles_pass_through():
    tab = doppler_table(np.arange(0.5, 120.0, 1.0), observable="doppler_count_2way", unit="cycles")
    out, rep = compress(tab, 60.0)
    assert rep.passthrough_rows == len(tab) == len(out) and rep.averaged_rows == 0


def test_other_observables_pass_through():
    dop = doppler_table(np.arange(0.5, 120.0, 1.0))
    rng = build(3, epoch=T0 + np.array([10, 20, 30], dtype="timedelta64[s]"), tag="receive",
                observable="range", value=[1.0, 2.0, 3.0], unit="RU", count_time=0.0, source="synthetic",
                record=[500, 501, 502], flags=0)
    out, rep = compress(pd.concat([dop, rng], ignore_index=True), 60.0)
    assert rep.passthrough_rows == 3 and rep.averaged_rows == 2
    assert out["epoch"].is_monotonic_increasing
    assert list(out.loc[out["observable"] == "range", "value"]) == [1.0, 2.0, 3.0]


def smooth_fit_residuals(tab, knot_s=120.0, degree=5):
    """Residuals (Hz, indexed by record) about a least-squares quintic spline fitted to each
    contiguous run (no gap > 5 s) of unflagged samples; runs shorter than 4 knots are skipped."""
    from scipy.interpolate import make_lsq_spline

    e = tab[tab["flags"] == 0].sort_values(["pass_id", "epoch"])
    ts = e["epoch"].to_numpy().view(np.int64) / 1e9
    run = np.r_[0, np.cumsum((np.diff(ts) > 5) | (np.diff(e["pass_id"].to_numpy()) != 0))]
    out = []
    for _, g in e.groupby(run):
        t = (g["epoch"] - g["epoch"].iloc[0]).dt.total_seconds().to_numpy()
        if t[-1] < 4 * knot_s:
            continue
        inner = np.linspace(0.0, t[-1], int(t[-1] // knot_s) + 1)[1:-1]
        knots = np.r_[[0.0] * (degree + 1), inner, [t[-1]] * (degree + 1)]
        fit = make_lsq_spline(t, g["value"].to_numpy(), knots, degree)
        out.append(pd.Series(g["value"].to_numpy() - fit(t), index=g["record"].to_numpy()))
    return pd.concat(out)


@pytest.mark.realdata
def test_grail_odf_compression(shared_data):
    from odpipe.preprocess.edit import edit

    data = odf.read(shared_data / "grail" / "grblugf2012_101_0350smmmv1.odf")
    tab, _ = edit(data.table, data.ramps)
    out, rep = compress(tab, 60.0, ramps=data.ramps)
    # nothing lost: every raw record is in exactly one output row
    recs = np.concatenate(list(out["source_records"]))
    assert len(recs) == len(tab) == np.unique(recs).size and len(rep.dropped) == 0
    # each compressed value is the mean of its 1-s values as read from the file
    raw = tab.set_index("record")["value"]
    comp = out[out["n_samples"] > 1]
    means = np.array([raw.loc[r].mean() for r in comp["source_records"]])
    assert np.max(np.abs(comp["value"].to_numpy() - means)) < 1e-9
    assert np.allclose(comp["count_time"], comp["n_samples"] * 1.0) and comp["count_time"].max() == 60.0
    # windows end at gaps, passes and ramp changes, so some are short; all are reported
    used = out["flags"] == 0
    assert rep.partial_rows == int((used & (out["count_time"] < 60.0)).sum())
    assert rep.passthrough_rows == int((~used).sum()) == int((tab["flags"] != 0).sum())
    # scatter about a smooth fit of the unramped (1-way) passes: 60-s windows average the 1-s residuals down
    res = smooth_fit_residuals(tab[~tab["ramped"]])
    full = comp[(comp["n_samples"] == 60)]
    full = full[[np.isin(r, res.index).all() for r in full["source_records"]]]
    r60 = np.array([res.loc[r].mean() for r in full["source_records"]])
    rms1, rms60 = res.std(), r60.std()
    print(f"GRAIL 101 1-way: rms 1 s {rms1:.4f} Hz, rms 60 s {rms60:.4f} Hz, ratio {rms1 / rms60:.2f}")
    assert len(r60) > 100
    assert rms1 / np.sqrt(60) < rms60 < rms1


@pytest.mark.parametrize("pass_id", [0, -1], ids=["given-pass", "assigned-pass"])
def test_running_doppler_counts_become_exact_doppler_in_hz(pass_id):
    # TRK-2-34 style: cycles of (Doppler + 1 MHz bias) accumulated from 0 at the first record, every 10 s;
    # the origin sample (count time 0) belongs to the pass its counts continue (the demo lost one window a pass)
    bias, dt = 1.0e6, 10.0
    t_s = np.arange(0.0, 600.0 + dt, dt)
    doppler = lambda t: 3000.0 + 2.0 * t + 50.0 * np.sin(t / 40.0)        # Hz, DSN sign
    cycles = lambda t: (bias + 3000.0) * t + t**2 - 2000.0 * np.cos(t / 40.0) + 2000.0  # integral from 0
    n = t_s.size
    epoch = np.datetime64("2010-11-20T04:38:00", "ns") + (t_s * 1e9).astype("timedelta64[ns]")
    tab = build(n, epoch=epoch, tag="interval_end", observable="doppler_count_2way", value=cycles(t_s), unit="cycles",
                count_time=np.r_[0.0, np.full(n - 1, dt)], station_tx="DSS-24", station_rx="DSS-24",
                spacecraft="2", band_up="S", band_down="S", pass_id=pass_id, record=np.arange(n), doppler_bias_hz=bias,
                media_m=np.r_[0.0, np.diff(0.5 * t_s**0.5)])    # delay change over each count interval
    out, report = compress(tab, 60.0)
    dop = out[out["observable"] == "doppler_2way"]
    assert report.dropped.empty
    assert len(dop) == 10 and (dop["unit"] == "Hz").all() and (dop["count_time"] == 60.0).all()
    start = (dop["epoch"].to_numpy() - epoch[0]) / np.timedelta64(1, "s") - 30.0   # tags are interval middles
    exact = (cycles(start + 60.0) - cycles(start)) / 60.0 - bias
    np.testing.assert_allclose(dop["value"], exact, atol=1e-6)
    np.testing.assert_allclose(dop["media_m"], 0.5 * (start + 60.0) ** 0.5 - 0.5 * start**0.5, rtol=1e-12)
    assert abs(exact[0] - doppler(start[0] + 30.0)) < 20.0  # the mean is near the mid-interval Doppler


def test_media_changes_of_doppler_rows_add_up_over_the_window():
    # six 10-s counts, each with the change of the delay over its own interval: the 60-s row's change is their sum
    n = 12
    epoch = np.datetime64("2010-11-21T01:14:10", "ns") + np.arange(n) * np.timedelta64(10, "s")
    delay = lambda t: 5.0 + 0.01 * t + 1e-5 * t**2          # m, a delay growing through the pass
    t_end = 10.0 * np.arange(1, n + 1)
    change = delay(t_end) - delay(t_end - 10.0)
    tab = build(n, epoch=epoch, tag="interval_end", observable="doppler_2way", value=100.0, unit="Hz",
                count_time=10.0, station_tx="PAD-11", station_rx="PAD-11", pass_id=0, record=np.arange(n),
                media_m=change, elevation_rx=np.linspace(0.2, 0.3, n))
    out, _ = compress(tab, 60.0)
    np.testing.assert_allclose(out["media_m"], [delay(60.0) - delay(0.0), delay(120.0) - delay(60.0)], rtol=1e-12)
    assert out["elevation_rx"].iloc[0] == pytest.approx(np.mean(np.linspace(0.2, 0.3, n)[:6]))  # angles average
