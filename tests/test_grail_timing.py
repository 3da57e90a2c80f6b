"""A station's time-tag offset (registry kind ``timing``) estimated with the orbit.

Truth: the 2-day HEO arc of test_od_simulate (no maneuver), two-way Doppler every 60 s and range every 600 s
from three stations, without range biases; then one station's rows carry tags ``DT`` late (each row's epoch
moved by +DT after simulation: the row tagged t saw t - DT). The fit estimates one offset per receiving
station: the late station's must come back within 3 sigma of DT and resolved, the others within 3 sigma of 0.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd

from bounds import max_z
from odpipe.od import ArcSetup, fit_arc
from odpipe.simulate.observe import simulate_tracking
from test_od_simulate import STATIONS, arc_state, force_model, measurement_setup, scenario

DT = 0.05  # s


def test_a_late_station_time_tag_offset_comes_back_within_3_sigma():
    sc = scenario(maneuver=False)
    plan = replace(sc["plan"], range_bias_sigma=0.0)
    table, _ = simulate_tracking(sc["truth"], plan, measurement_setup(), np.random.default_rng(5))
    late = STATIONS[1]
    table.loc[table["station_rx"] == late, "epoch"] += pd.Timedelta(seconds=DT)
    table = table.sort_values("epoch", kind="stable", ignore_index=True)
    setup = ArcSetup("SC", sc["t0"], sc["t1"], arc_state(sc), force_model(), measurement_setup(),
                     range_bias_sigma=None, time_offset_sigma=1.0)
    sol = fit_arc(table, setup)
    assert sol.converged
    p = sol.parameters.set_index("name")
    for st in STATIONS:
        est, sig = p.loc[f"timing.{st}", "estimate"], p.loc[f"timing.{st}", "sigma"]
        true = DT if st == late else 0.0
        assert abs(est - true) < max_z(len(STATIONS)) * sig, (st, est, sig)
        assert sig < 0.1 * DT, (st, sig)
