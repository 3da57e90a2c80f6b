"""Blunders against the a priori orbit (preprocess.apriori_blunder_k), on rows spaced as GRAIL's ramped Doppler is.

Simulated: one day of the HEO arc of test_od_simulate, two-way Doppler of three stations, thinned so that
consecutive rows of a pass are 60 to 240 s apart (windows following uplink ramp segments). One row gets
a 44 mm/s blunder (the size of GRAIL-B 04-10 DSS-34's first window, which the values-based spike test
missed there). The test on the residuals against an a priori orbit 1 km / 1 cm/s off must flag that row
and no other.
"""

from __future__ import annotations

import numpy as np

from odpipe.dynamics.propagator import propagate
from odpipe.measurements import compute
from odpipe.preprocess.apriori_blunders import apriori_blunders
from test_od_simulate import arc_state, force_model, measurement_setup, scenario

BLUNDER = 0.044  # m/s along the line of sight


def test_a_blunder_in_unevenly_spaced_doppler_is_found_against_the_a_priori_orbit():
    sc = scenario(days=1.0, maneuver=False)
    table = sc["table"][sc["table"]["observable"] == "doppler_2way"].reset_index(drop=True)
    rng = np.random.default_rng(2)
    keep = np.zeros(len(table), bool)
    for _, g in table.groupby(["station_rx", "pass_id"]):
        i = g.index[0]
        while i <= g.index[-1]:
            keep[i] = True
            i += int(rng.integers(1, 5))   # next row 60-240 s later
    table = table[keep].reset_index(drop=True)
    hit = int(table.groupby("pass_id").head(1).index[1])   # a pass's first row, as on 04-10
    value = table["value"].to_numpy(float).copy()
    setup = measurement_setup()
    apriori = propagate(arc_state(sc), sc["t0"], sc["t0"] - 600.0, force_model(), with_stm=False)
    x_back = apriori.state(sc["t0"] - 600.0)[0]
    apriori = propagate(x_back, sc["t0"] - 600.0, sc["t1"] + 60.0, force_model(), with_stm=False)
    to_los = compute(table.iloc[[hit]], {"SC": sc["truth"]}, setup).to_los[0]
    value[hit] += BLUNDER / to_los
    table["value"] = value
    use = np.ones(len(table), bool)
    found = apriori_blunders(table, apriori, setup, "SC", 10.0, use)
    assert list(np.flatnonzero(found)) == [hit]
