"""Without process noise the smoothed epoch solution equals batch least squares.

One filter-smoother pass about the a priori reference (1 km / 1 cm/s off, with a
maneuver, SRP scale and per-pass range biases) against
:func:`odpipe.estimation.least_squares.batch_least_squares` (normal equations, Cholesky)
on the same rows, whose epoch partials are chained here from the problem's own
``predict``/``transition`` over the segments.
"""

from __future__ import annotations

import numpy as np

from odpipe.estimation.least_squares import batch_least_squares
from odpipe.od import ArcSetup, ManeuverPlan, fit_arc
from test_od_simulate import arc_state, force_model, measurement_setup, scenario


def epoch_partials(problem, x0):
    """d computed / d registry vector at t_start for every row, through the segments' transitions."""
    H = np.zeros((problem.times.size, x0.size))
    t, x, Phi_cum = problem.t_start, x0, np.eye(x0.size)
    while t < problem.t_end:
        seg = problem.segment(t, x)
        rows = np.arange(seg.lo, seg.hi)
        if rows.size:
            H[rows] = problem.predict(t, x, rows)[1] @ Phi_cum
        x, Phi = problem.transition(t, seg.b, x)
        Phi_cum = Phi @ Phi_cum
        t = seg.b
    return H


def test_one_pass_smoother_equals_batch_least_squares():
    sc = scenario()
    setup = ArcSetup("SC", sc["t0"], sc["t1"], arc_state(sc), force_model(), measurement_setup(),
                     sigma_position=10e3, sigma_velocity=0.1,
                     maneuvers=(ManeuverPlan("tcm1", sc["t_man"]),),
                     data_sigma={"range": 1.0, "doppler_2way": 1e-4}, max_iter=1, edit_k=(np.inf,))
    sol = fit_arc(sc["table"], setup)
    reg, prob = sol.registry, sol.problem
    assert len(prob._segments) == 2            # the maneuver splits the arc
    x_ref = reg.apriori
    H = epoch_partials(prob, x_ref)
    res = sol.residuals
    batch = batch_least_squares(H, res["prefit"].to_numpy(), res["sigma"].to_numpy(), np.diag(reg.sigma**2))
    dx = sol.solution.smoothed_x[0] - x_ref
    P = sol.solution.smoothed_P[0]
    sig = np.sqrt(np.diag(batch.P))
    # the pass moves the state by ~1 km (hundreds of sigma); both solvers agree to 1e-6 sigma
    assert np.max(np.abs(batch.x[:3])) > 500.0
    np.testing.assert_array_less(np.abs(dx - batch.x) / sig, 1e-6)
    np.testing.assert_allclose(np.sqrt(np.diag(P)), sig, rtol=1e-6)
    corr_b = batch.P / np.outer(sig, sig)
    corr_f = P / np.outer(np.sqrt(np.diag(P)), np.sqrt(np.diag(P)))
    np.testing.assert_allclose(corr_f, corr_b, atol=1e-6)
    np.testing.assert_allclose(res["postfit"].to_numpy() / res["sigma"].to_numpy(),
                               batch.postfit / res["sigma"].to_numpy(), atol=1e-5)
