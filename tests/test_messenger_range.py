"""MESSENGER's sequential range (odf07155.odf) against the ODF spec and against the same file's Doppler.

External references: TRK-2-18 (DSN 820-013) for the range record: data type 37 is sequential range in range
units (RU), ambiguous modulo 2^(lowest component + 6) RU; its reference frequency is the transmitter's
frequency at the time tag; item 20 is the uplink coder in-phase time offset from the tag (s). Moyer
(DESCANSO Monograph 2) ch. 13: two-way range R = F * integral(f_T dt, t1, t3) mod M with F = 221/(749*2)
for an X-band uplink, and ramped two-way Doppler counts the received phase, here as the ODF gives it,
M2 f_REF - f_received (M2 = 880/749). Together they give the DSN's own range check (DRVID, range minus
integrated Doppler): the change of R between two range points is F [integral(f_T, t3a, t3b) -
integral(f_received, t3a, t3b) / M2], from the ramp table and the Doppler records alone, no orbit.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from odpipe.preprocess.stale_uplink import into_segment
from parsers import odf
from parsers.ramps import RampStore

RUNS = Path(__file__).resolve().parents[1] / "runs"
F_X, M2_XX = 221 / (749 * 2), 880 / 749
MODULUS = 2.0 ** 20  # lowest component 14 in every record
PASS_BREAK = pd.Timedelta("2h")
STALE_S = 599  # s into a 1200-s ramp segment: where the three failing passes take their uplink phase


@pytest.fixture(scope="module")
def data(shared_data):
    d = odf.read(shared_data / "messenger" / "odf07155.odf")
    rng = d.table[d.table["observable"] == "range"].sort_values("epoch").reset_index(drop=True)
    new_pass = (rng["station_rx"] != rng["station_rx"].shift()) | (rng["epoch"].diff() > PASS_BREAK)
    rng["pass"] = np.cumsum(new_pass.to_numpy())
    return d, RampStore(d.ramps), rng


def wrap(x):
    """Into [-M/2, M/2) RU."""
    return np.mod(np.asarray(x) + MODULUS / 2, MODULUS) - MODULUS / 2


def drvid(table, store, station, a, b, ramps=None) -> float:
    """Range minus integrated Doppler (RU, wrapped) between range rows ``a`` and ``b`` of ``station``.

    With ``ramps``, each range is first read as F [phase_T(s) - phase_T(t1)] instead of F [phase_T(t3) -
    phase_T(t1)]: the uplink phase taken at s = STALE_S into the tag's ramp record (:func:`into_segment`).

    The received frequency is the ODF's M2 f_REF - D of the station's 60-s two-way counts (time tags at the
    count middles), counts off a 7-point running median by more than 2 Hz (the file's blunders) left out and
    the rest interpolated linearly on a 1-s grid; NaN when the counts leave a gap of more than 90 s.
    """
    dop = table[(table["observable"] == "doppler_2way") & (table["station_rx"] == station)
                & (table["station_tx"] == station)].sort_values("epoch")
    recv = M2_XX * dop["reference_hz"] - dop["value"]
    keep = (recv - recv.rolling(7, center=True, min_periods=3).median()).abs() <= 2.0
    t = (dop["epoch"][keep] - a.epoch).dt.total_seconds().to_numpy()
    f = recv[keep].to_numpy()
    n = int(round((b.epoch - a.epoch).total_seconds()))
    grid = np.arange(n) + 0.5
    j = np.clip(np.searchsorted(t, grid), 1, len(t) - 1)
    if np.max(np.minimum(np.abs(t[j] - grid), np.abs(t[j - 1] - grid))) > 90.0:
        return np.nan
    received = np.sum(np.interp(grid, t, f))  # cycles over [t3a, t3b]
    sent = store.phase(station, np.array([a.epoch.to_datetime64()]), np.array([b.epoch.to_datetime64()]))[0]
    miss = b.value - a.value - F_X * (sent - received / M2_XX)
    if ramps is not None:
        (xa, xb), (ta, tb) = into_segment(ramps, station, [a.epoch, b.epoch], STALE_S), (a.epoch, b.epoch)
        ta, tb = ta.to_datetime64(), tb.to_datetime64()
        miss += F_X * (store.phase(station, np.array([xb]), np.array([tb]))[0]
                       - store.phase(station, np.array([xa]), np.array([ta]))[0])
    return float(wrap(miss))


@pytest.mark.realdata
def test_range_records_decode_as_the_spec_defines_them(data):
    d, store, rng = data
    assert len(rng) == 61 and set(rng["odf_data_type"]) == {37}  # sequential range, X up and down
    assert set(rng["band_up"]) == {"X"} and (rng["station_tx"] == rng["station_rx"]).all()
    assert set(rng["item15"]) == {14}
    np.testing.assert_array_equal(rng["range_modulus_ru"], MODULUS)
    assert ((rng["value"] >= 0) & (rng["value"] < MODULUS)).all()
    assert (rng["downlink_delay_s"] == 0).all() and (rng["uplink_delay_s"] == 0).all()  # no delay calibration
    # reference frequency = the transmitter's ramp at the time tag, to the field's 1 mHz (checks the tags and
    # which ramp table applies, in every pass)
    f = store.frequency(rng["station_tx"].to_numpy(), rng["epoch"].to_numpy())
    assert np.max(np.abs(rng["reference_hz"].to_numpy() - f)) < 1.1e-3
    # one uplink coder in-phase time per pass (tag - item 20), 767-774 s before its first point
    inphase = rng["epoch"] - pd.to_timedelta(rng["item20"], unit="s")
    assert (inphase.groupby(rng["pass"]).nunique() == 1).all()
    first = rng.groupby("pass")["epoch"].first() - inphase.groupby(rng["pass"]).first()
    assert first.dt.total_seconds().between(767, 774).all()


@pytest.mark.realdata
def test_drvid_keeps_the_first_dss63_pass_and_rejects_the_others(data):
    """DRVID between consecutive range points: DSS-63's 06-04 pass within 10 RU (measured |d| <= 8 RU, 1.1 m);
    in the other three passes every pair misses by more than 1e3 RU (a random value would be within 1e3 RU
    with probability 0.002): their range is not the plain definition, and the run config reads exactly those
    passes' range by ``[[preprocess.range_uplink_epoch]]`` (the test below)."""
    d, store, rng = data
    rows = []
    for p, g in rng.groupby("pass"):
        pts = list(g.itertuples())
        for a, b in zip(pts[:-1], pts[1:]):
            rows.append((p, a.station_rx, a.epoch, drvid(d.table, store, a.station_rx, a, b)))
    out = pd.DataFrame(rows, columns=["pass", "station", "start", "drvid"]).dropna()
    print(out.to_string())
    good = out["pass"] == 1
    assert rng.loc[rng["pass"] == 1, "station_rx"].iloc[0] == "DSS-63" and good.sum() >= 15
    assert out.loc[good, "drvid"].abs().max() < 10.0
    assert (out.loc[~good, "drvid"].abs() > 1e3).all() and out.loc[~good, "pass"].nunique() == 3
    cfg = tomllib.loads((RUNS / "messenger_2007_06_04.toml").read_text())
    assert "edit_windows" not in cfg["preprocess"]
    read = np.zeros(len(rng), bool)
    for w in cfg["preprocess"]["range_uplink_epoch"]:
        assert w["reason"] and w["into_ramp_s"] == STALE_S
        read |= ((rng["station_rx"] == w["station_rx"]) & (rng["epoch"] >= pd.Timestamp(w["start"]))
                 & (rng["epoch"] <= pd.Timestamp(w["end"]))).to_numpy()
    np.testing.assert_array_equal(read, (rng["pass"] != 1).to_numpy())  # the run reads exactly those passes so


@pytest.mark.realdata
def test_uplink_epoch_sections_need_a_reason_and_an_order(tmp_path, shared_data):
    import re

    from odpipe.operations.schema import ConfigError
    from odpipe.pipeline.config import load_config

    text = re.sub(r'"\.\./\.\./shared/data/', f'"{shared_data}/', (RUNS / "messenger_2007_06_04.toml").read_text())
    text = re.sub(r'^reason = ".*"$', 'reason = " "', text, count=1, flags=re.M)  # the first section's
    text = text.replace('end = "2007-06-05T05:00:00"', 'end = "2007-06-04T19:00:00"', 1)
    (tmp_path / "arc.toml").write_text(text)
    with pytest.raises(ConfigError) as err:
        load_config(tmp_path / "arc.toml")
    msg = str(err.value)
    assert "preprocess.range_uplink_epoch[0].reason" in msg and "say why the rows are removed" in msg
    assert "preprocess.range_uplink_epoch[0].end" in msg and "before the start" in msg
    (tmp_path / "arc.toml").write_text(text.replace("into_ramp_s = 599.0", "into_ramp_s = -1.0", 1))
    with pytest.raises(ConfigError, match=r"preprocess\.range_uplink_epoch\[0\]\.into_ramp_s\] -1\.0 must be positive"):
        load_config(tmp_path / "arc.toml")
    (tmp_path / "arc.toml").write_text(text.replace("into_ramp_s = 599.0\n", "", 1))   # measured per file: no default
    with pytest.raises(ConfigError, match=r"preprocess\.range_uplink_epoch\[0\]\.into_ramp_s"):
        load_config(tmp_path / "arc.toml")


@pytest.mark.realdata
def test_the_failing_passes_take_the_uplink_phase_599_s_into_the_ramp_segment(data):
    """Why DSS-14 (06-04/05), DSS-43 and DSS-63 (06-05) fail DRVID, for the points late in their ramp segments.

    Read as R = F [phase_T(s) - phase_T(t1)] with s = 599 s into the 20-min ramp record holding the tag, every
    point whose tag lies at least that far into its record (DSS-14 184 s, DSS-43 521 s, DSS-63 430 s after s)
    agrees with the next such point (3600 s later) within 30 RU (measured |d| <= 24 RU, 16 intervals), where the
    plain reading misses by 1e4-5e5 RU (test above). The points earlier in their records (22) are not explained.
    The good pass (DSS-63 06-04) does not follow the rule: its late points (1052 s into their records) miss by
    more than 1e4 RU under it (measured 1.16e5-1.61e5). Against the fitted orbit with the good pass's bias the rule
    leaves <= 4 RU on the 20 late points (docs/validation.md; the run fits them)."""
    d, store, rng = data
    late, good, early = [], [], 0
    for p, g in rng.groupby("pass"):
        st = g["station_rx"].iloc[0]
        is_late = ~np.isnat(into_segment(d.ramps, st, g["epoch"].to_numpy(), STALE_S))
        early += int((~is_late).sum()) if p != 1 else 0
        pts = list(g[is_late].itertuples())
        for a, b in zip(pts[:-1], pts[1:]):
            if b.epoch - a.epoch <= pd.Timedelta("3700s"):
                (good if p == 1 else late).append(drvid(d.table, store, st, a, b, ramps=d.ramps))
    late, good = (np.array(x)[np.isfinite(x)] for x in (late, good))
    print(np.round(late), np.round(good))
    assert early == 22 and len(late) >= 15 and np.max(np.abs(late)) < 30.0
    assert len(good) >= 7 and np.min(np.abs(good)) > 1e4
