"""Simulated DSN tracking of a known trajectory, for fits against truth (tests, benchmarks).

Two-way (or one-way, against ``setup.oscillators``) Doppler, count-averaged and
tagged at the interval end, and two-way range (metres, at reception) from each
station while the spacecraft is above
an elevation mask, computed with the product's own measurement models on the
truth trajectory, plus Gaussian noise and a constant range bias per pass.
Noise and biases are given along the line of sight (m/s, m) and converted to
row units. Rows come out time ordered with ``pass_id`` set and ``flags`` 0.

:func:`libration_arc` builds the long-arc case of the tests and benchmarks.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

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


ARTEMIS_CASE = Path(__file__).resolve().parents[2] / "runs" / "artemis_p2_like.toml"


def libration_arc(days: float = 14.0, case_path=ARTEMIS_CASE) -> dict:
    """An ARTEMIS-P2-like Earth-Moon L1 arc over the case's first ``days``, tracked by DSS-14/43/63.

    Truth from :func:`odpipe.simulate.truth.simulate_truth` (cylinder SRP, Gauss-Markov RTN
    accelerations, station-keeping and attitude burns executed with errors); 240-s two-way
    Doppler (0.1 mm/s) and range every 1200 s (2 m, 5-m bias per pass) above 10 deg. DSS-43's
    Doppler is twice noisier than stated and five other Doppler rows carry 30-sigma
    blunders. ``setup``: an :class:`~odpipe.od.arc.ArcSetup` estimating state, SRP scale,
    accelerations in the case's batches, dV and firing epoch (10 mm/s, 10 s) of each burn and
    per-pass range biases, started 1 km / 1 cm/s off, reweighting off.
    Returns dict(truth, table, blunders (table index), noisy (bool per row), setup).
    """
    from odpipe.dynamics.forces import EmpiricalRTN, ImpulsiveManeuver
    from odpipe.estimation.registry import GaussMarkov
    from odpipe.measurements import MeasurementSetup
    from odpipe.simulate.case import load
    from odpipe.simulate.truth import simulate_truth
    from odpipe.time import utc_to_tdb

    from .arc import ArcSetup, ManeuverPlan

    meas = MeasurementSetup.default()
    case = load(case_path).shortened(days)
    rng = np.random.default_rng(case.seed)
    truth = simulate_truth(case, meas.ephemeris, rng)
    plan = TrackingPlan(("DSS-14", "DSS-43", "DSS-63"), case.start, case.end - np.timedelta64(60, "s"),
                        doppler_step=240.0, range_step=1200.0, sigma_doppler=1e-4, sigma_range=2.0,
                        range_bias_sigma=5.0, spacecraft="SC")
    table, _ = simulate_tracking(truth.trajectory, plan, meas, rng)
    noisy = ((table["station_rx"] == "DSS-43") & (table["observable"] == "doppler_2way")).to_numpy()
    table.loc[noisy, "value"] += np.sqrt(3.0) * table.loc[noisy, "sigma"] * rng.standard_normal(noisy.sum())
    dop = np.flatnonzero((table["observable"] == "doppler_2way").to_numpy() & ~noisy)
    blunders = table.index[dop[rng.choice(dop.size, 5, replace=False)]]
    table.loc[blunders, "value"] += 30.0 * table.loc[blunders, "sigma"]
    nominal = [c for c in truth.force_model.components if not isinstance(c, (EmpiricalRTN, ImpulsiveManeuver))]
    t0, t1 = float(utc_to_tdb(case.start)), float(utc_to_tdb(case.end))
    x0 = truth.trajectory.state(np.array([t0]))[0]
    st = case.stochastic
    setup = ArcSetup("SC", t0, t1, x0 + np.array([1e3, -1e3, 1e3, 1e-2, -1e-2, 1e-2]) / np.sqrt(3.0),
                     replace(truth.force_model, components=nominal), meas,
                     stochastic=GaussMarkov(float(st["tau_s"]), float(st["sigma"]), float(st["batch_s"])),
                     maneuvers=tuple(ManeuverPlan(m["name"], float(e), tuple(m["dv"]), 0.01, 10.0)
                                     for m, e in zip(truth.maneuvers, truth.epochs)),
                     lookback=300.0, data_sigma={"range": 2.0, "doppler_2way": 1e-4})
    return dict(truth=truth, table=table, blunders=set(blunders), noisy=noisy, setup=setup)
