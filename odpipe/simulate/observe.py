"""Simulated observables: TrackingTable rows computed by odpipe.measurements on the truth, plus errors.

Per row: value = model(truth, media) + (noise + range bias + spin) / to_los, where
the media delay is what :func:`odpipe.media.apply.calibrate` gives for the row
(troposphere from the TRK-2-23 .TRO cards on the DSN seasonal model, standard
atmosphere elsewhere, Niell mapping; ionosphere from the .ION cards of DSN passes) and enters through the table's ``media_m``
column and the models' own media term. Noise is white along the line of sight
(m, m/s), the range bias one draw per pass, the spin signature the
count-averaged rate of a = antenna_offset * sin(w t + phi). Doppler is
two-way, tagged at the count end; DSN uplinks follow a linear ramp per pass.
The written table keeps ``elevation_rx``, ``azimuth_rx`` and ``rtlt_s`` so the
calibration stage can recompute the media delays.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from odpipe.measurements import compute
from odpipe.media.apply import calibrate
from odpipe.constants import NS_PER_S
from odpipe.simulate.schedule import StateOnly, passes, sample_epochs
from parsers.ramps import RampStore
from parsers.table import RAMP_COLUMNS, build

RANGE_MODULUS_RU = float(2**24)
S_BAND_RATIO = 240.0 / 221.0


@dataclass
class Observations:
    table: pd.DataFrame      # the simulated TrackingTable (with media_m, elevation_rx, azimuth_rx, rtlt_s)
    ramps: pd.DataFrame      # uplink ramp table
    errors: pd.DataFrame     # per row: model (no media), media, noise, bias, spin (row units)


def _rows(net, sc, epochs, observable, pass_id, unit, count):
    n = epochs.size
    ramped = net.ramp_rate_sigma > 0
    extra = {"range_modulus": RANGE_MODULUS_RU if unit == "RU" else np.nan}
    return build(n, epoch=epochs, observable=observable, unit=unit, station_tx=net.station, station_rx=net.station,
                 spacecraft=sc, tag="interval_end" if count else "receive", count_time=count, band_up=net.band,
                 band_down=net.band, uplink_hz=np.nan if ramped else net.uplink_hz, ramped=ramped,
                 transponder_ratio=S_BAND_RATIO, value=0.0, sigma=np.nan, pass_id=pass_id, flags=0,
                 source="simulated", record=-1, **extra)


def _ramp(net, window, rng) -> dict:
    start = window[0] - np.timedelta64(3600 * NS_PER_S, "ns")
    return {"station": net.station, "start": start, "end": window[1], "freq_hz": net.uplink_hz + 1e3 * rng.standard_normal(),
            "rate_hz_s": net.ramp_rate_sigma * rng.standard_normal(), "band": net.band, "source": "simulated", "record": -1}


def plan_rows(case, traj, setup, rng) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(rows without values, ramp table) of every network's passes."""
    traj = StateOnly(traj)
    sc = str(case.spacecraft)
    parts, ramps, pid = [], [], 0
    for net in case.networks:
        for window in passes(traj, setup, net, sc, case.start, case.end):
            parts.append(_rows(net, sc, sample_epochs(window, net.doppler_count_s), "doppler_2way", pid, "Hz",
                               net.doppler_count_s))
            if net.range_step_s > 0:
                parts.append(_rows(net, sc, sample_epochs(window, net.range_step_s), "range", pid,
                                   "RU" if net.format == "trk234" else "s", 0.0))
            if net.ramp_rate_sigma > 0:
                ramps.append(_ramp(net, window, rng))
            pid += 1
    table = pd.concat(parts, ignore_index=True).sort_values(["epoch", "station_rx", "observable"], kind="stable")
    ramp_table = pd.DataFrame(ramps, columns=list(RAMP_COLUMNS)).astype({"start": "datetime64[ns]", "end": "datetime64[ns]"})
    return table.reset_index(drop=True), ramp_table


def geometry(table, traj, setup) -> pd.DataFrame:
    """elevation_rx, azimuth_rx (rad) and rtlt_s (s) of each row at its time tag."""
    sc = table["spacecraft"].iloc[0]
    probe = table.assign(count_time=0.0, tag="receive", ramped=False)
    out = {}
    for col, obs, unit in (("elevation_rx", "angle_el", "rad"), ("azimuth_rx", "angle_az", "rad"), ("rtlt_s", "range", "s")):
        out[col] = compute(probe.assign(observable=obs, unit=unit), {sc: traj}, setup).value
    return pd.DataFrame(out, index=table.index)


def spin_signature(t_s: np.ndarray, count: np.ndarray, amplitude: float, rate: float, phase: float) -> np.ndarray:
    """Count-averaged LOS rate (m/s) of a*sin(w t + phi) over intervals ending at ``t_s`` (s)."""
    return amplitude * (np.sin(rate * t_s + phase) - np.sin(rate * (t_s - count) + phase)) / count


def dsn_passes(table) -> list[tuple]:
    """(station, first tag, last tag) of each DSN pass of a planned table (for the .ION cards)."""
    dsn = table[table["station_rx"].str.startswith("DSS-")]
    g = dsn.groupby("pass_id")
    return list(zip(g["station_rx"].first(), g["epoch"].min().to_numpy("datetime64[ns]"),
                    g["epoch"].max().to_numpy("datetime64[ns]")))


def observe(case, table, ramps, traj, setup, media_model, catalog, rng) -> Observations:
    """Values and errors of planned rows (:func:`plan_rows`) of ``traj``; sets setup.ramps from ``ramps``."""
    traj = StateOnly(traj)
    setup.ramps = RampStore(ramps) if len(ramps) else None
    table = pd.concat([table, geometry(table, traj, setup)], axis=1)
    cal, _ = calibrate(table, media_model, ramps=ramps if len(ramps) else None, catalog=catalog, order=None)
    sc = {table["spacecraft"].iloc[0]: traj}
    clean = compute(table, sc, setup)
    table["media_m"] = cal["media_m"].to_numpy()
    ev = compute(table, sc, setup)
    nets = {n.station: n for n in case.networks}
    st = table["station_rx"].map(nets)
    is_range = (table["observable"] == "range").to_numpy()
    sigma = np.where(is_range, [n.sigma_range for n in st], [n.sigma_doppler for n in st])
    noise = sigma * rng.standard_normal(len(table))
    pid = table["pass_id"].to_numpy()
    bias_sigma = np.array([n.range_bias_sigma for n in st])
    bias = np.where(is_range, (rng.standard_normal(pid.max() + 1)[pid]) * bias_sigma, 0.0)
    body = case.body
    t_s = (table["epoch"].to_numpy() - case.start).astype(np.int64) / 1e9
    ct = table["count_time"].to_numpy(float)
    spin = np.zeros(len(table))
    if float(body.get("antenna_offset_m", 0.0)) > 0:
        w = 2 * np.pi * float(body["spin_rpm"]) / 60.0
        spin[~is_range] = spin_signature(t_s[~is_range], ct[~is_range], float(body["antenna_offset_m"]), w,
                                         2 * np.pi * rng.random())
    table["value"] = ev.value + (noise + bias + spin) / ev.to_los
    table["sigma"] = sigma / ev.to_los
    table["record"] = np.arange(len(table))
    errors = pd.DataFrame({"model": clean.value, "media": ev.value - clean.value, "noise": noise / ev.to_los,
                           "bias": bias / ev.to_los, "spin": spin / ev.to_los, "to_los": ev.to_los,
                           "sigma_los": sigma})
    return Observations(table, ramps, errors)
