"""Considered station coordinates: same estimate, larger (consider) covariance.

Station ITRS errors of 0.5 m per axis are considered, not estimated (Table 4.1):
the smoothed epoch estimate must equal the fit without them, and the consider
covariance must exceed the data-only one by a positive semi-definite amount.
"""

from __future__ import annotations

import numpy as np

from odpipe.od import ArcSetup, ManeuverPlan, fit_arc
from test_od_simulate import arc_state, force_model, measurement_setup, scenario


def test_considered_stations_leave_the_estimate_and_inflate_the_covariance():
    sc = scenario()
    kw = dict(maneuvers=(ManeuverPlan("tcm1", sc["t_man"]),), data_sigma={"range": 1.0, "doppler_2way": 1e-4},
              max_iter=1, edit_k=(np.inf,))
    plain = fit_arc(sc["table"], ArcSetup("SC", sc["t0"], sc["t1"], arc_state(sc), force_model(),
                                          measurement_setup(), **kw))
    cons = fit_arc(sc["table"], ArcSetup("SC", sc["t0"], sc["t1"], arc_state(sc), force_model(),
                                         measurement_setup(), station_sigma=0.5, **kw))
    reg = cons.registry
    assert reg.n_estimated == len(plain.registry) and len(reg) == reg.n_estimated + 9
    n = reg.n_estimated
    P = plain.solution.smoothed_P[0]
    sig = np.sqrt(np.diag(P))
    np.testing.assert_array_less(np.abs(cons.solution.x0[:n] - plain.solution.x0) / sig, 1e-6)
    np.testing.assert_allclose(cons.solution.smoothed_P[0][:n, :n], P, rtol=1e-6, atol=0)
    extra = cons.solution.P0[:n, :n] - P
    eig = np.linalg.eigvalsh(extra / np.outer(sig, sig))
    assert eig.min() > -1e-9 and eig.max() > 1e-3
    grow = np.sqrt(np.diag(cons.covariances[0])) / sig[:6]
    assert np.all(grow >= 1.0) and grow.max() > 1.01
