"""Ramp store: evaluation and findings checked against exact decimal arithmetic on the
independent ASCII listing of odf07155.odf (messenger/odf07155.txt), against tudat's
published check of one ramp record, and on hand-made tables with known defects."""

from __future__ import annotations

from decimal import Decimal, getcontext

import numpy as np
import pandas as pd
import pytest

from parsers import odf
from parsers.ramps import RampStore

getcontext().prec = 40
T1950 = np.datetime64("1950-01-01", "ns")


def listing_ramps(text: str) -> list[tuple]:
    """(station, start s, rate, freq, end s) as Decimals from the ramp groups of the listing."""
    rows, in_ramps = [], False
    for line in text.splitlines():
        if line.startswith("---") and "Group" in line:
            in_ramps = "Ramp" in line
        f = line.split()
        if in_ramps and len(f) == 5 and f[0].isdigit():
            rows.append((f"DSS-{int(f[0]):02d}",) + tuple(Decimal(x) for x in f[1:]))
    return rows


def at(seconds: Decimal):
    """datetime64[ns] and sub-ns remainder (s) of a decimal time past 1950."""
    ns = int(seconds * 10**9)
    return T1950 + np.timedelta64(ns, "ns"), float(seconds - Decimal(ns) / 10**9)


def exact_phase(rows, station, t0: Decimal, t1: Decimal) -> Decimal:
    """Integral of the listed piecewise-linear frequency from t0 to t1, in exact decimals."""
    total = Decimal(0)
    for st, s, r, f, e in rows:
        a, b = max(s, t0), min(e, t1)
        if st == station and b > a:
            total += f * (b - a) + r / 2 * ((b - s) ** 2 - (a - s) ** 2)
    return total


@pytest.fixture(scope="module")
def messenger(shared_data):
    d = odf.read(shared_data / "messenger/odf07155.odf")
    return RampStore(d.ramps), listing_ramps((shared_data / "messenger/odf07155.txt").read_text())


@pytest.mark.realdata
def test_frequency_at_every_segment_start_and_end_matches_listing(messenger):
    store, rows = messenger
    assert len(rows) == 169
    live = [r for r in rows if r[4] > r[1]]
    for station in {r[0] for r in live}:
        seg = [r for r in live if r[0] == station]
        starts = [at(r[1]) for r in seg]
        f0 = store.frequency(station, [t for t, _ in starts], [o for _, o in starts])
        np.testing.assert_allclose(f0, [float(r[3]) for r in seg], rtol=0, atol=2e-6)
        # just before each end: 1 ns earlier plus a 1e-9 s offset lands exactly on the end
        ends = [at(r[4]) for r in seg]
        f1 = store.frequency(station, [t - np.timedelta64(1, "ns") for t, _ in ends], 1e-9)
        np.testing.assert_allclose(f1, [float(r[3] + r[2] * (r[4] - r[1])) for r in seg], rtol=0, atol=2e-6)


@pytest.mark.realdata
def test_tudat_published_ramp_record(messenger):
    # tudat unitTestOdfReader: DSS-63 ramp 5 starts 1812101116 s, 0.09568 Hz/s, 7177004073.170830727 Hz
    store, _ = messenger
    seg = store.segments[store.segments["station"] == "DSS-63"].iloc[5]
    assert seg["start"] == T1950 + np.timedelta64(1812101116, "s")
    assert seg["end"] == T1950 + np.timedelta64(1812101962, "s")
    assert seg["rate_hz_s"] == 0.09568 and abs(seg["freq_hz"] - 7177004073.170830727) < 1e-6


@pytest.mark.realdata
def test_jumps_are_the_listed_retunings(messenger):
    store, rows = messenger
    expected = set()
    for prev, nxt in zip(rows, rows[1:]):
        if prev[0] == nxt[0] and prev[4] == nxt[1] and prev[4] > prev[1]:
            jump = nxt[3] - (prev[3] + prev[2] * (prev[4] - prev[1]))
            if abs(jump) > Decimal("1e-3"):
                expected.add((prev[0], int(nxt[1]), round(float(jump), 4)))
    found = store.findings[store.findings["kind"] == "jump"]
    got = {(s, int((t - T1950) // np.timedelta64(1, "s")), round(j, 4))
           for s, t, j in zip(found["station"], found["start"].to_numpy(), found["detail"])}
    assert got == expected and len(expected) == 9
    kinds = store.findings.groupby("kind").size().to_dict()
    assert kinds == {"jump": 9, "zero_length": 3}  # one end-of-ramp marker per station


@pytest.mark.realdata
@pytest.mark.parametrize("t0,t1", [("1812101100.25", "1812103400.75"),   # 5 segments, a 100 Hz/s ramp
                                   ("1812103470.123456789012", "1812103530.123456789012"),  # 60 s count
                                   ("1812139800", "1812141600")])         # retunes and steep ramps
def test_phase_matches_exact_integral_of_listing(messenger, t0, t1):
    store, rows = messenger
    a, b = Decimal(t0), Decimal(t1)
    ref = exact_phase(rows, "DSS-63", a, b)
    (ta, oa), (tb, ob) = at(a), at(b)
    ph = store.phase("DSS-63", ta, tb, oa, ob)[0]
    assert abs(Decimal(ph) - ref) <= ref * Decimal("2e-16") + Decimal("1e-4")
    fm = store.mean_frequency("DSS-63", ta, tb, oa, ob)[0]
    assert abs(Decimal(fm) - ref / (b - a)) < Decimal("2e-6")


@pytest.mark.realdata
def test_outside_coverage_is_nan(messenger):
    store, _ = messenger
    before = T1950 + np.timedelta64(1812100000, "s")
    inside = T1950 + np.timedelta64(1812101200, "s")
    assert np.isnan(store.frequency("DSS-63", before)).all()
    assert np.isnan(store.frequency("DSS-99", inside)).all()
    assert np.isnan(store.phase("DSS-63", before, inside)).all()
    assert np.isfinite(store.phase("DSS-63", inside, inside + np.timedelta64(60, "s"))).all()


@pytest.mark.realdata
def test_grail_store_spans_files_and_covers_every_two_way_uplink(shared_data):
    data = [odf.read(p) for p in sorted((shared_data / "grail").glob("*.odf"))]
    store = RampStore(*(d.ramps for d in data))
    assert len(store.segments) == sum(len(d.ramps) for d in data)
    assert store.stations == sorted(set().union(*(set(d.ramps["station"]) for d in data)))
    gaps = store.findings[store.findings["kind"] == "gap"]
    assert (gaps["detail"] > 0).all() and len(gaps) >= 1
    for d in data:
        two = d.table[d.table["observable"] == "doppler_2way"]
        # the uplink of a lunar 2-way count left ~2.5 s before reception
        t = two["epoch"].to_numpy() - np.timedelta64(3, "s")
        f = store.frequency(two["station_tx"].to_numpy(), t)
        assert np.isfinite(f).all() and (abs(f - 2.1e9) < 1e5).all()  # S-band uplink


def _table(rows):
    return pd.DataFrame(rows, columns=["station", "start", "end", "freq_hz", "rate_hz_s"]).assign(
        start=lambda d: pd.to_datetime(d["start"]), end=lambda d: pd.to_datetime(d["end"]),
        band="X", source="hand", record=lambda d: np.arange(len(d)))


def test_findings_on_hand_made_defects():
    a = _table([
        ("DSS-25", "2020-01-01T00:00:00", "2020-01-01T00:01:00", 7.1e9, 1.0),      # ends at 7.1e9 + 60
        ("DSS-25", "2020-01-01T00:01:00", "2020-01-01T00:02:00", 7.1e9 + 60, 0.0),  # continuous join
        ("DSS-25", "2020-01-01T00:01:30", "2020-01-01T00:03:00", 7.1e9 + 70, 0.0),  # 30 s overlap, jump
        ("DSS-25", "2020-01-01T00:05:00", "2020-01-01T00:04:00", 7.1e9, 0.0),       # reversed
        ("DSS-25", "2020-01-01T00:10:00", None, 7.1e9, 0.0),                        # gap 420 s, open end
    ])
    b = a.iloc[:2].assign(source="other")  # the first two again, from another file
    store = RampStore(a, b)
    f = store.findings.set_index("kind")
    assert sorted(f.index) == ["duplicate", "duplicate", "gap", "jump", "open_end", "overlap", "reversed"]
    assert f.loc["overlap", "detail"] == 30 and f.loc["gap", "detail"] == 420
    assert f.loc["reversed", "detail"] == 60 and f.loc["jump", "detail"] == 10
    t = np.datetime64("2020-01-01T00:00:30", "ns")
    assert store.frequency("DSS-25", t)[0] == 7.1e9 + 30
    # 30 s of the 1 Hz/s ramp from 7.1e9 + 30, then 30 s at 7.1e9 + 60 (the overlap cut it at 00:01:30)
    expected = 7.1e9 * 60 + (60**2 - 30**2) / 2 + 30 * 60
    assert store.phase("DSS-25", t, t + np.timedelta64(60, "s"))[0] == pytest.approx(expected, abs=1e-4)
    assert store.mean_frequency("DSS-25", t, t + np.timedelta64(60, "s"))[0] == pytest.approx(7.1e9 + 52.5, abs=1e-6)
    assert np.isnan(store.phase("DSS-25", t, np.datetime64("2020-01-01T00:12:00", "ns")))  # across the gap
    far = np.datetime64("2030-01-01", "ns")
    assert store.frequency("DSS-25", far)[0] == 7.1e9  # the open last segment runs on


def test_stations_as_array_equal_separate_calls():
    store = RampStore(_table([("DSS-14", "2020-01-01", "2020-01-02", 2.1e9, 0.5),
                              ("DSS-43", "2020-01-01", "2020-01-02", 2.2e9, -0.5)]))
    t = np.datetime64("2020-01-01T01:00:00", "ns") + np.arange(4) * np.timedelta64(1, "s")
    st = np.array(["DSS-43", "DSS-14", "DSS-99", "DSS-14"], dtype=object)
    got = store.frequency(st, t)
    assert got[0] == store.frequency("DSS-43", t[0])[0] and got[1] == store.frequency("DSS-14", t[1])[0]
    assert np.isnan(got[2]) and got[3] == 2.1e9 + 0.5 * 3603


def test_rejects_a_table_without_ramp_columns():
    with pytest.raises(ValueError, match="missing columns"):
        RampStore(pd.DataFrame({"station": ["DSS-14"]}))
