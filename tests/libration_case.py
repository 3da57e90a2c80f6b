"""The long-arc case of the OD tests and ``benchmarks/bench_od.py``: an ARTEMIS-P2-like Earth-Moon L1 arc.

``libration_arc(days)`` simulates the truth of ``runs/artemis_p2_like.toml`` with
:mod:`odpipe.simulate` and its tracking with :func:`odpipe.simulate.observe.simulate_tracking`.
The truth's SRP is the case's spinning cylinder (specular and diffuse reflection: a force off
the Sun line of ~1e-8 m/s^2); the filter's is a cannonball of the cylinder's side-on cross-section
with Cr = 1.3 and an estimated scale, so the shape error is left to its RTN accelerations.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np

from odpipe.dynamics.forces import EmpiricalRTN, ImpulsiveManeuver, SolarRadiationPressure
from odpipe.estimation.registry import GaussMarkov
from odpipe.measurements import MeasurementSetup
from odpipe.od.arc import ArcSetup, ManeuverPlan
from odpipe.simulate.case import load
from odpipe.simulate.observe import simulate_tracking
from odpipe.simulate.schedule import TrackingPlan
from odpipe.simulate.truth import simulate_truth
from odpipe.time import utc_to_tdb

ARTEMIS_CASE = Path(__file__).resolve().parents[1] / "runs" / "artemis_p2_like.toml"


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
    body = case.body
    cannonball = SolarRadiationPressure(cr_area=1.3 * 2.0 * body.radius_m * body.length_m)
    nominal = [cannonball if isinstance(c, SolarRadiationPressure) else c for c in truth.force_model.components
               if not isinstance(c, (EmpiricalRTN, ImpulsiveManeuver))]
    t0, t1 = float(utc_to_tdb(case.start)), float(utc_to_tdb(case.end))
    x0 = truth.trajectory.state(np.array([t0]))[0]
    st = case.stochastic
    setup = ArcSetup("SC", t0, t1, x0 + np.array([1e3, -1e3, 1e3, 1e-2, -1e-2, 1e-2]) / np.sqrt(3.0),
                     replace(truth.force_model, components=nominal), meas,
                     stochastic=GaussMarkov(st.tau_s, st.sigma, st.batch_s),
                     maneuvers=tuple(ManeuverPlan(m["name"], float(e), tuple(m["dv"]), 0.01, 10.0)
                                     for m, e in zip(truth.maneuvers, truth.epochs)),
                     lookback=300.0, data_sigma={"range": 2.0, "doppler_2way": 1e-4})
    return dict(truth=truth, table=table, blunders=set(blunders), noisy=noisy, setup=setup)
