"""One-way Doppler: the spacecraft oscillator's bias and drift are fitted with the orbit.

Truth: X-band oscillator 8.4 GHz with a 0.05 Hz bias (1.8 mm/s) and a 2e-7 Hz/s drift
(0.035 Hz over the 2 days); one-way Doppler every 60 s (0.1 mm/s) and two-way range
every 600 s from the same three stations, over the 2-day HEO arc of test_od_truth
(without the maneuver). The fit starts from a zero bias and drift.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from odpipe.od import ArcSetup, fit_arc, simulate_tracking
from test_od_simulate import arc_state, force_model, measurement_setup, scenario

F0, BIAS, DRIFT = 8.4e9, 0.05, 2e-7


def test_oscillator_bias_drift_and_state_within_3_sigma():
    sc = scenario(maneuver=False)
    t_ref = sc["t0"]
    truth_setup = replace(measurement_setup(), oscillators={"SC": (F0, BIAS, DRIFT, t_ref)})
    plan = replace(sc["plan"], doppler="doppler_1way", uplink_hz=F0, range_bias_sigma=0.0)
    table, _ = simulate_tracking(sc["truth"], plan, truth_setup, np.random.default_rng(5))
    assert set(table["observable"]) == {"doppler_1way", "range"}
    fit_setup = replace(measurement_setup(), oscillators={"SC": (F0, 0.0, 0.0, t_ref)})
    setup = ArcSetup("SC", sc["t0"], sc["t1"], arc_state(sc), force_model(), fit_setup,
                     data_sigma={"range": 1.0, "doppler_1way": 1e-4}, range_bias_sigma=None,
                     oscillator_sigma=(1.0, 1e-5))
    sol = fit_arc(table, setup)
    assert sol.converged and 0.95 < sol.history[-1]["postfit_rms"] < 1.05
    p = sol.parameters.set_index("name")
    for name, true in (("SC.osc_bias", BIAS), ("SC.osc_drift", DRIFT)):
        est, sig = p.loc[name, "estimate"], p.loc[name, "sigma"]
        assert abs(est - true) < 3 * sig and sig < 0.1 * abs(true), (name, est, sig)
    err = sol.states[0] - sc["x0"]
    assert np.all(np.abs(err) < 3 * np.sqrt(np.diag(sol.covariances[0])))
