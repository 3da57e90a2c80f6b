"""Simulated observables: TrackingTable rows computed by odpipe.measurements on a truth trajectory, plus errors.

One code path makes every simulated value, :func:`simulate_values`: value = model(truth) +
(noise + range bias + signature) / to_los, with white noise along the line of sight (m, m/s),
one range bias per pass and an optional systematic signature (LOS units), converted to row
units by the models' ``to_los``. Two plans feed it planned rows:

* a case (:mod:`odpipe.simulate.case`, the demo): :func:`plan_rows` schedules the passes of each
  network rule, :func:`observe` adds the media delay :func:`odpipe.media.apply.calibrate` gives
  for each row (troposphere from the TRK-2-23 .TRO cards on the DSN seasonal model, standard
  atmosphere elsewhere, Niell mapping; ionosphere from the .ION cards of DSN passes) through the
  table's ``media_m`` column, and the spin signature, the count-averaged rate of
  a = antenna_offset * sin(w t + phi). Doppler is two-way, tagged at the count end; DSN uplinks
  follow a linear ramp per pass. The table keeps ``elevation_rx``, ``azimuth_rx`` and ``rtlt_s``
  so the calibration stage can recompute the media delays.
* a :class:`~odpipe.simulate.schedule.TrackingPlan` (the tests, benchmarks): :func:`simulate_tracking`
  tracks from every station whenever the spacecraft is above the mask, no media.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from odpipe.constants import NS_PER_S
from odpipe.measurements import compute
from odpipe.measurements.computed import Computed
from odpipe.media.apply import calibrate
from odpipe.simulate.schedule import StateOnly, TrackingPlan, passes, sample_epochs, visible_epochs
from parsers.ramps import RampStore
from parsers.table import RAMP_COLUMNS, build

RANGE_MODULUS_RU = float(2**24)
S_BAND_RATIO = 240.0 / 221.0


@dataclass
class Observations:
    table: pd.DataFrame      # the simulated TrackingTable (with media_m, elevation_rx, azimuth_rx, rtlt_s)
    ramps: pd.DataFrame      # uplink ramp table
    errors: pd.DataFrame     # per row: model (no media), media, noise, bias, spin (row units)


@dataclass
class SimulatedValues:
    """What :func:`simulate_values` added to each row, along the line of sight (m or m/s)."""

    computed: Computed       # the models on the truth (with the table's media_m); to_los: LOS units per row unit
    noise: np.ndarray
    bias: np.ndarray         # the pass's range bias on range rows, 0 elsewhere
    signature: np.ndarray
    sigma_los: np.ndarray


def planned_rows(epochs, observable: str, unit: str, station: str, spacecraft: str, pass_id, count_time: float,
                 band: str, uplink_hz: float, **columns) -> pd.DataFrame:
    """Rows to simulate (value 0, sigma NaN): tagged at the interval end when ``count_time`` > 0, else at
    reception; one-way Doppler has no transmitting station and no uplink band."""
    one_way = observable == "doppler_1way"
    return build(epochs.size, epoch=epochs, observable=observable, unit=unit, station_tx="" if one_way else station,
                 station_rx=station, spacecraft=spacecraft, tag="interval_end" if count_time else "receive",
                 count_time=count_time, band_up="" if one_way else band, band_down=band, uplink_hz=uplink_hz,
                 value=0.0, sigma=np.nan, pass_id=pass_id, flags=0, source="simulated", record=-1, **columns)


def simulate_values(table: pd.DataFrame, trajectories: dict, setup, sigma_los, bias_sigma, rng,
                    signature=None) -> SimulatedValues:
    """Set ``value``, ``sigma`` and ``record`` of planned rows of the truth ``trajectories`` (in place).

    ``sigma_los``: white noise (LOS units), per row or one; ``bias_sigma``: range bias (m) per row or one,
    drawn once per pass id; ``signature(rng)``: systematic LOS error per row, drawn after the noise and
    the biases (None: none)."""
    ev = compute(table, trajectories, setup)
    is_range = (table["observable"] == "range").to_numpy()
    noise = sigma_los * rng.standard_normal(len(table))
    pid = table["pass_id"].to_numpy()
    bias = np.where(is_range, rng.standard_normal(pid.max() + 1 if pid.size else 0)[pid] * bias_sigma, 0.0)
    extra = np.zeros(len(table)) if signature is None else signature(rng)
    table["value"] = ev.value + (noise + bias + extra) / ev.to_los
    table["sigma"] = sigma_los / ev.to_los
    table["record"] = np.arange(len(table))
    return SimulatedValues(ev, noise, bias, extra, np.broadcast_to(sigma_los, (len(table),)))


def plan_rows(case, traj, setup, rng) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(rows without values, ramp table) of every network's passes."""
    traj = StateOnly(traj)
    sc = str(case.spacecraft)
    parts, ramps, pid = [], [], 0
    for net in case.networks:
        ramped = net.ramp_rate_sigma > 0
        common = dict(station=net.station, spacecraft=sc, band=net.band, uplink_hz=np.nan if ramped else net.uplink_hz,
                      ramped=ramped, transponder_ratio=S_BAND_RATIO)
        for window in passes(traj, setup, net, sc, case.start, case.end):
            parts.append(planned_rows(sample_epochs(window, net.doppler_count_s), "doppler_2way", "Hz", pass_id=pid,
                                      count_time=net.doppler_count_s, range_modulus=np.nan, **common))
            if net.range_step_s > 0:
                ru = net.format == "trk234"
                parts.append(planned_rows(sample_epochs(window, net.range_step_s), "range", "RU" if ru else "s",
                                          pass_id=pid, count_time=0.0, range_modulus=RANGE_MODULUS_RU if ru else np.nan,
                                          **common))
            if ramped:
                ramps.append(_ramp(net, window, rng))
            pid += 1
    table = pd.concat(parts, ignore_index=True).sort_values(["epoch", "station_rx", "observable"], kind="stable")
    ramp_table = pd.DataFrame(ramps, columns=list(RAMP_COLUMNS)).astype({"start": "datetime64[ns]", "end": "datetime64[ns]"})
    return table.reset_index(drop=True), ramp_table


def _ramp(net, window, rng) -> dict:
    start = window[0] - np.timedelta64(3600 * NS_PER_S, "ns")
    return {"station": net.station, "start": start, "end": window[1], "freq_hz": net.uplink_hz + 1e3 * rng.standard_normal(),
            "rate_hz_s": net.ramp_rate_sigma * rng.standard_normal(), "band": net.band, "source": "simulated", "record": -1}


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
    st = table["station_rx"].map({n.station: n for n in case.networks})
    is_range = (table["observable"] == "range").to_numpy()
    sigma = np.where(is_range, [n.sigma_range for n in st], [n.sigma_doppler for n in st])
    bias_sigma = np.array([n.range_bias_sigma for n in st])
    v = simulate_values(table, sc, setup, sigma, bias_sigma, rng, signature=_spin(case, table, is_range))
    to_los = v.computed.to_los
    errors = pd.DataFrame({"model": clean.value, "media": v.computed.value - clean.value, "noise": v.noise / to_los,
                           "bias": v.bias / to_los, "spin": v.signature / to_los, "to_los": to_los,
                           "sigma_los": v.sigma_los})
    return Observations(table, ramps, errors)


def _spin(case, table, is_range):
    """The case's spin signature in its Doppler rows (a draw of the phase), or None without an antenna offset."""
    body = case.body
    if not body.antenna_offset_m > 0:
        return None
    t_s = (table["epoch"].to_numpy() - case.start).astype(np.int64) / 1e9
    ct = table["count_time"].to_numpy(float)
    w = 2 * np.pi * body.spin_rpm / 60.0

    def draw(rng):
        spin = np.zeros(len(table))
        spin[~is_range] = spin_signature(t_s[~is_range], ct[~is_range], body.antenna_offset_m, w,
                                         2 * np.pi * rng.random())
        return spin
    return draw


def simulate_tracking(trajectory, plan: TrackingPlan, setup, rng: np.random.Generator
                      ) -> tuple[pd.DataFrame, np.ndarray]:
    """(TrackingTable of noisy Doppler and range of ``trajectory`` per ``plan``, range bias per pass id (m)).

    Doppler (``plan.doppler``) over intervals of ``doppler_step`` whose both ends are above the mask in
    the same pass, tagged at the end; two-way range (m) every ``range_step`` at reception. The trajectory
    must cover the span plus a few seconds of light time before it."""
    parts = []
    common = dict(spacecraft=plan.spacecraft, band=plan.band, uplink_hz=plan.uplink_hz, ramped=False,
                  transponder_ratio=np.nan)
    for st, (epochs, ids) in visible_epochs(trajectory, plan, setup).items():
        ok = (ids[1:] >= 0) & (ids[1:] == ids[:-1])
        parts.append(planned_rows(epochs[1:][ok], plan.doppler, "Hz", st, pass_id=ids[1:][ok],
                                  count_time=plan.doppler_step, **common))
        secs = (epochs - epochs[0]).astype("timedelta64[ns]").astype(np.int64) * 1e-9
        rsel = (ids >= 0) & (np.mod(secs, plan.range_step) == 0)
        parts.append(planned_rows(epochs[rsel], "range", "m", st, pass_id=ids[rsel], count_time=0.0, **common))
    table = pd.concat(parts, ignore_index=True).sort_values("epoch", kind="stable").reset_index(drop=True)
    is_range = (table["observable"] == "range").to_numpy()
    v = simulate_values(table, {plan.spacecraft: trajectory}, setup,
                        np.where(is_range, plan.sigma_range, plan.sigma_doppler), plan.range_bias_sigma, rng)
    pid = table["pass_id"].to_numpy()
    per_pass = np.zeros(pid.max() + 1 if pid.size else 0)
    per_pass[pid[is_range]] = v.bias[is_range]
    return table, per_pass
