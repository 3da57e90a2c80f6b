"""Simulated DSN tracking of a known trajectory, for fits against truth (tests, benchmarks).

Two-way (or one-way, against ``setup.oscillators``) Doppler, count-averaged and
tagged at the interval end, and two-way range (metres, at reception) from each
station while the spacecraft is above
an elevation mask, computed with the product's own measurement models on the
truth trajectory, plus Gaussian noise and a constant range bias per pass.
Noise and biases are given along the line of sight (m/s, m) and converted to
row units. Rows come out time ordered with ``pass_id`` set and ``flags`` 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from odpipe.measurements import compute
from parsers.table import build


@dataclass(frozen=True)
class TrackingPlan:
    """What to simulate: stations, span (UTC datetime64), cadences (s), mask (rad), noise (LOS units);
    doppler: 'doppler_2way' or 'doppler_1way' (reference frequency ``uplink_hz``)."""

    stations: tuple
    start: np.datetime64
    end: np.datetime64
    doppler_step: float = 60.0
    range_step: float = 600.0
    min_elevation: float = np.radians(10.0)
    sigma_doppler: float = 1e-4          # m/s
    sigma_range: float = 1.0             # m
    range_bias_sigma: float = 0.0        # m, one draw per pass
    uplink_hz: float = 7.16e9
    band: str = "X"
    spacecraft: str = "SC"
    doppler: str = "doppler_2way"


def _rows(n, plan, epoch, observable, station, unit, count, tag, pass_id):
    one_way = observable == "doppler_1way"
    return build(n, epoch=epoch, observable=observable, unit=unit, station_tx="" if one_way else station,
                 station_rx=station, spacecraft=plan.spacecraft, tag=tag, count_time=count,
                 band_up="" if one_way else plan.band, band_down=plan.band,
                 uplink_hz=plan.uplink_hz, ramped=False, transponder_ratio=np.nan, value=0.0, sigma=np.nan,
                 pass_id=pass_id, flags=0, source="simulated", record=np.arange(n))


def visible_epochs(trajectory, plan, setup) -> dict:
    """Per station: candidate epochs (UTC, every ``doppler_step``) above the mask and their pass ids."""
    step = np.timedelta64(int(plan.doppler_step * 1e9), "ns")
    epochs = np.arange(np.datetime64(plan.start, "ns"), np.datetime64(plan.end, "ns") + step, step)
    out, next_pass = {}, 0
    for st in plan.stations:
        probe = _rows(epochs.size, plan, epochs, "angle_el", st, "rad", 0.0, "receive", -1)
        el = compute(probe, {plan.spacecraft: trajectory}, setup).value
        up = el > plan.min_elevation
        run = np.cumsum(np.diff(np.concatenate([[False], up])) == 1)
        ids = np.where(up, run - 1 + next_pass, -1)
        next_pass += int(run[-1]) if run.size else 0
        out[st] = (epochs, ids)
    return out


def simulate_tracking(trajectory, plan: TrackingPlan, setup, rng: np.random.Generator
                      ) -> tuple[pd.DataFrame, np.ndarray]:
    """(TrackingTable of noisy two-way Doppler and range of ``trajectory``, range bias per pass id (m)).

    The trajectory must cover the span plus a few seconds of light time before it."""
    parts = []
    for st, (epochs, ids) in visible_epochs(trajectory, plan, setup).items():
        # Doppler interval [e - step, e] needs both ends above the mask in the same pass
        ok = (ids[1:] >= 0) & (ids[1:] == ids[:-1])
        e = epochs[1:][ok]
        parts.append(_rows(e.size, plan, e, plan.doppler, st, "Hz", plan.doppler_step, "interval_end", ids[1:][ok]))
        secs = (epochs - epochs[0]).astype("timedelta64[ns]").astype(np.int64) * 1e-9
        rsel = (ids >= 0) & (np.mod(secs, plan.range_step) == 0)
        parts.append(_rows(int(rsel.sum()), plan, epochs[rsel], "range", st, "m", 0.0, "receive", ids[rsel]))
    table = pd.concat(parts, ignore_index=True).sort_values("epoch", kind="stable").reset_index(drop=True)
    ev = compute(table, {plan.spacecraft: trajectory}, setup)
    is_range = (table["observable"] == "range").to_numpy()
    sigma_los = np.where(is_range, plan.sigma_range, plan.sigma_doppler)
    pass_ids = table["pass_id"].to_numpy()
    bias = plan.range_bias_sigma * rng.standard_normal(pass_ids.max() + 1 if pass_ids.size else 0)
    los = sigma_los * rng.standard_normal(len(table)) + np.where(is_range, bias[pass_ids], 0.0)
    table["value"] = ev.value + los / ev.to_los
    table["sigma"] = sigma_los / ev.to_los
    table["record"] = np.arange(len(table))
    return table, bias
