"""The compute() entry point on a mixed TrackingTable: wiring, partial groups vs end-to-end finite differences."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from odpipe.environment.stations import Station, StationCatalog
from odpipe.measurements.compute import MeasurementSetup, compute
from odpipe.measurements.crosslink import ClockModel
from odpipe.measurements.lighttime import anchor_from_utc
from parsers.ramps import RampStore
from parsers.table import build
from test_measurements_helpers import LinearTrajectory

T0 = np.datetime64("2025-03-01T06:00:00", "ns")
ROWS = [  # observable, unit, tx, rx, sc, sc2, tag, count, band_up, band_down, uplink_hz, ramped
    ("range", "RU", "DSS-14", "DSS-14", "A", "", "receive", 0.0, "X", "X", 7.16e9, False),
    ("range", "m", "DSS-25", "DSS-25", "A", "", "receive", 0.0, "X", "X", 7.16e9, False),
    ("range", "s", "DSS-63", "DSS-63", "A", "", "receive", 0.0, "S", "S", 2.1e9, False),
    ("doppler_2way", "Hz", "DSS-14", "DSS-14", "A", "", "interval_mid", 60.0, "X", "X", 7.16e9, False),
    ("doppler_2way", "Hz", "DSS-25", "DSS-25", "A", "", "interval_end", 60.0, "X", "X", np.nan, True),
    ("doppler_3way", "Hz", "DSS-14", "DSS-63", "A", "", "interval_mid", 10.0, "S", "S", 2.1e9, False),
    ("doppler_1way", "Hz", "", "DSS-25", "A", "", "interval_mid", 60.0, "", "X", 8.4e9, False),
    ("angle_az", "rad", "", "DSS-14", "A", "", "receive", 0.0, "", "X", np.nan, False),
    ("angle_el", "rad", "", "DSS-14", "A", "", "receive", 0.0, "", "X", np.nan, False),
    ("range_rate", "m/s", "", "DSS-14", "A", "", "receive", 0.0, "", "", np.nan, False),
    ("sst_range", "m", "", "", "A", "B", "receive", 0.0, "", "", np.nan, False),
    ("sst_doppler", "m/s", "", "", "A", "B", "interval_end", 10.0, "", "", np.nan, False),
    ("dowr_sum", "m", "", "", "A", "B", "receive", 0.0, "", "", np.nan, False),
    ("dowr_diff", "m", "", "", "A", "B", "receive", 0.0, "", "", np.nan, False),
    ("vlbi_wb_sc", "s", "", "DSS-14", "A", "", "receive", 0.0, "", "", np.nan, False),
]
NREP = 3


def _table():
    rows = [r for r in ROWS for _ in range(NREP)]
    n = len(rows)
    cols = list(zip(*rows))
    epoch = T0 + (np.arange(n) * 431).astype("timedelta64[s]")
    return build(n, epoch=epoch, observable=cols[0], unit=cols[1], station_tx=cols[2], station_rx=cols[3],
                 spacecraft=cols[4], spacecraft_2=np.array(cols[5], dtype=object), tag=cols[6], count_time=cols[7],
                 band_up=cols[8], band_down=cols[9], uplink_hz=cols[10], ramped=cols[11],
                 transponder_ratio=np.nan, value=0.0)


def _trajs(dx_a=np.zeros(6), dx_b=np.zeros(6)):
    t0 = anchor_from_utc(T0)[0][0]
    a = LinearTrajectory(np.array([2.0e8, -2.5e8, 1.2e8]) + dx_a[:3], np.array([600.0, 800.0, -200.0]) + dx_a[3:], t0, "earth")
    b = LinearTrajectory(np.array([-3.0e7, 3.2e7, 1.0e6]) + dx_b[:3], np.array([-2000.0, -1900.0, 300.0]) + dx_b[3:], t0,
                         "earth")
    return {"A": a, "B": b}


@pytest.fixture(scope="module")
def setup():
    base = MeasurementSetup.default()
    ramp = pd.DataFrame({"station": ["DSS-25"], "start": [T0 - np.timedelta64(1, "h")], "end": [T0 + np.timedelta64(9, "h")],
                         "freq_hz": [7.16e9], "rate_hz_s": [0.3], "band": ["X"], "source": ["t"], "record": [0]})
    base.ramps = RampStore(ramp)
    base.oscillators = {"A": (6e-11, 1.2e-15, 0.0)}
    base.clocks = {"A": ClockModel(1e-6, 1e-10, 0.0, 8e8)}
    return base


def test_every_row_is_computed_or_says_why(setup):
    tbl = _table()
    ev = compute(tbl, _trajs(), setup)
    ok = tbl["observable"] != "vlbi_wb_sc"
    assert np.all(np.isfinite(ev.value[ok])) and np.all(ev.status[ok] == "")
    assert np.all(np.isnan(ev.value[~ok])) and all("no model" in s for s in ev.status[~ok])
    assert ev.partials["state:A"].shape == (len(tbl), 6) and ev.names["station:DSS-14"] == ["x", "y", "z"]
    # the ODF-style range in seconds is the round trip: ~2 x 3.4e8 m / c
    rs = ev.value[(tbl["unit"] == "s") & (tbl["observable"] == "range")]
    assert np.all((rs > 2.0) & (rs < 2.6))
    # two-way Doppler and range-rate agree in sign
    dop = ev.value[tbl["observable"] == "doppler_2way"]
    rr = ev.value[tbl["observable"] == "range_rate"]
    assert np.all(np.sign(dop) == np.sign(rr[0]))


def test_state_partials_of_every_row_vs_end_to_end_finite_differences(setup):
    tbl = _table()
    ok = (tbl["observable"] != "vlbi_wb_sc").to_numpy()
    ev = compute(tbl, _trajs(), setup)
    for sc in ("A", "B"):
        fd = np.zeros((len(tbl), 6))
        for i, h in enumerate([50.0] * 3 + [0.5] * 3):  # big steps: the first rows sit at the epoch (tiny dv effect)
            dx = np.zeros(6)
            dx[i] = h
            up = compute(tbl, _trajs(*(dx, np.zeros(6))[:: 1 if sc == "A" else -1]), setup).value
            dn = compute(tbl, _trajs(*(-dx, np.zeros(6))[:: 1 if sc == "A" else -1]), setup).value
            fd[:, i] = (up - dn) / (2 * h)
        an = ev.partials.get(f"state:{sc}", np.zeros_like(fd))
        scale = np.max(np.abs(fd[ok]), axis=1, keepdims=True) + 1e-300
        err = np.abs(an[ok] - fd[ok]) / scale
        assert np.max(err) < 2e-4, (sc, tbl["observable"][ok].to_numpy()[np.argmax(np.max(err, axis=1))])


def test_station_partials_vs_moving_the_antenna(setup):
    tbl = _table()
    sel = (tbl["station_rx"].isin(["DSS-14"]).to_numpy() | tbl["station_tx"].isin(["DSS-14"]).to_numpy()) \
        & (tbl["observable"] != "vlbi_wb_sc").to_numpy()
    ev = compute(tbl, _trajs(), setup)
    fd = np.zeros((len(tbl), 3))
    for i in range(3):
        vals = []
        for s in (1, -1):
            moved = [Station(st.name, st.r_itrs + s * 100.0 * np.eye(3)[i], st.v_itrs_per_yr, st.epoch_year)
                     if st.name == "DSS-14" else st for st in setup.stations]
            vals.append(compute(tbl, _trajs(), MeasurementSetup(**{**setup.__dict__, "stations": StationCatalog(moved)})).value)
        fd[:, i] = (vals[0] - vals[1]) / 200.0  # 100 m steps: Earth-orientation jitter (~1e-5 m) stays below 1e-3
    an = ev.partials["station:DSS-14"]
    scale = np.max(np.abs(fd[sel]), axis=1, keepdims=True)
    assert np.max(np.abs(an[sel] - fd[sel]) / scale) < 1e-3
    assert np.all(an[~sel] == 0)


def test_media_enters_with_its_scale_and_partial(setup):
    tbl = _table()
    base = compute(tbl, _trajs(), setup)
    tbl["media_m"] = 3.0
    ev = compute(tbl, _trajs(), MeasurementSetup(**{**setup.__dict__, "media_scale": 2.0}))
    m = (tbl["unit"] == "m").to_numpy() & (tbl["observable"] == "range").to_numpy()
    np.testing.assert_allclose(ev.value[m] - base.value[m], 2.0 * 1.5, rtol=1e-9)  # round-trip 3 m = 1.5 m of range
    np.testing.assert_allclose(ev.partials["media_scale"][m, 0], 1.5, rtol=1e-12)
    d = (tbl["observable"] == "doppler_2way").to_numpy()
    # 3 m more round-trip path over 60 s is 0.05 m/s of range-rate, i.e. 0.05 / to_los Hz
    np.testing.assert_allclose(ev.partials["media_scale"][d, 0] * ev.to_los[d], 3.0 / 2 / 60, rtol=1e-12)


def test_a_model_registered_by_name_is_used_by_compute(setup):
    """The registry is the one extension point: a model registered under a new name serves its rows."""
    import importlib

    C = importlib.import_module("odpipe.measurements.compute")  # the module (the package exports the function)

    tbl = _table()
    rr = tbl[tbl["observable"] == "range_rate"].reset_index(drop=True)
    renamed = rr.assign(observable="range_rate_new")
    assert "no model" in compute(renamed, _trajs(), setup).status[0]
    C.model("range_rate_new")(C.MODELS["range_rate"])
    try:
        ev_new, ev_old = compute(renamed, _trajs(), setup), compute(rr, _trajs(), setup)
    finally:
        del C.MODELS["range_rate_new"]
    np.testing.assert_array_equal(ev_new.value, ev_old.value)
    np.testing.assert_array_equal(ev_new.partials["state:A"], ev_old.partials["state:A"])
    assert set(C.MODELS) >= {"range", "doppler_2way", "doppler_3way", "doppler_1way", "angle_az", "angle_el",
                             "range_rate", "sst_range", "sst_doppler", "dowr_sum", "dowr_diff"}


def test_rows_prepared_once_evaluate_as_fresh_rows(setup):
    """A fit evaluates the same rows with new trajectories at every iteration from one ``prepare``: what each group
    keeps from its rows (columns, M2, range-unit factors, media) gives, trajectory after trajectory, the values and
    partials of a fresh ``compute`` of the rows, to the last bit."""
    from odpipe.measurements.compute import prepare

    tbl = _table()
    tbl["media_m"] = np.linspace(1.0, 4.0, len(tbl))
    tbl["range_modulus"] = np.where(tbl["unit"] == "RU", 2.0 ** 20, np.nan)
    prepared = prepare(tbl)
    for dx in (np.zeros(6), np.array([3e3, -2e3, 1e3, 0.5, -0.3, 0.2]), np.zeros(6)):
        again, fresh = compute(tbl, _trajs(dx), setup, prepared), compute(tbl, _trajs(dx), setup)
        assert np.array_equal(again.value, fresh.value, equal_nan=True) and np.array_equal(again.status, fresh.status)
        assert again.partials.keys() == fresh.partials.keys()
        for k in fresh.partials:
            assert np.array_equal(again.partials[k], fresh.partials[k], equal_nan=True), k
