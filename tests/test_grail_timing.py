"""A station's time-tag offset (registry kind ``timing``) estimated with the orbit.

Truth: one day of the HEO arc of test_od_simulate (no maneuver), two-way Doppler every 60 s and range every 600 s
from three stations, without range biases; then one station's rows carry tags ``DT`` late (each row's epoch
moved by +DT after simulation: the row tagged t saw t - DT). The fit estimates one offset per receiving
station but the one with the most rows (a common offset is the orbit's own time shift: unobservable), so each
must come back within 3 sigma of its offset relative to that station, resolved to a tenth of DT.
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
    sc = scenario(days=1.0, maneuver=False)
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
    ref = table["station_rx"].value_counts().index[0]
    assert f"timing.{ref}" not in p.index
    for st in set(STATIONS) - {ref}:
        est, sig = p.loc[f"timing.{st}", "estimate"], p.loc[f"timing.{st}", "sigma"]
        true = (DT if st == late else 0.0) - (DT if ref == late else 0.0)
        assert abs(est - true) < max_z(len(STATIONS) - 1) * sig, (st, est, sig)
        assert sig < 0.1 * DT, (st, sig)
