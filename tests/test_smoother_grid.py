"""Smoother output on any grid: the fit does not depend on where it reports, and the
smoothed covariance never exceeds the filtered one (smoothing only adds data)."""

import numpy as np

from odpipe.estimation.fit import FitOptions, Observations, fit
from tests.test_estimation_montecarlo import ARC, BATCH, _setup, _truth


def test_estimates_at_measurement_times_and_grid_invariance():
    reg, prob, t, sigma, kind = _setup()
    rng = np.random.default_rng(9)
    truth = _truth(reg, prob, rng)
    y = np.einsum("mk,mk->m", prob.H_rows, truth(t)) + rng.normal(size=t.size) * sigma
    obs = Observations(t, y, sigma, kind)
    coarse = fit(prob, obs, 0.0, ARC, FitOptions(block=BATCH, max_iter=1))
    fine = fit(prob, obs, 0.0, ARC, FitOptions(block=BATCH, max_iter=1,
                                               output_at_measurements=True))
    assert np.all(np.isin(t, fine.grid)) and fine.grid.size > 3 * coarse.grid.size
    s = np.sqrt(np.diag(coarse.smoothed_P_consider[0]))
    assert np.max(np.abs(fine.x0 - coarse.x0) / s) < 1e-8
    assert np.max(np.abs(fine.P0 - coarse.P0) / np.outer(s, s)) < 1e-8
    # common grid epochs carry the same filtered and smoothed estimates
    k_f = np.searchsorted(fine.grid, coarse.grid)
    for a, b in ((fine.smoothed_x, coarse.smoothed_x), (fine.filtered_x, coarse.filtered_x)):
        sig = np.sqrt(np.diagonal(coarse.smoothed_P_consider, axis1=1, axis2=2))
        assert np.max(np.abs(a[k_f] - b) / sig) < 1e-7
    # post-fit residual of every row = observed - H x_smoothed(t_row) on the fine grid
    k = np.searchsorted(fine.grid, t)
    post = y - np.einsum("mk,mk->m", prob.H_rows, fine.smoothed_x[k])
    assert np.max(np.abs(post - fine.residuals["postfit"]) / sigma) < 1e-6
    # smoothing never loses information
    n = reg.n_estimated
    d = (np.diagonal(fine.filtered_P, axis1=1, axis2=2)
         - np.diagonal(fine.smoothed_P_consider, axis1=1, axis2=2))[:, :n]
    assert np.all(d >= -1e-9 * np.diagonal(fine.filtered_P, axis1=1, axis2=2)[:, :n])


def test_rows_outside_the_arc_are_flagged_not_used():
    from odpipe.estimation.fit import OUTSIDE_ARC

    reg, prob, t, sigma, kind = _setup()
    rng = np.random.default_rng(10)
    y = np.einsum("mk,mk->m", prob.H_rows, _truth(reg, prob, rng)(t)) + rng.normal(size=t.size) * sigma
    half = ARC / 2
    full = fit(prob, Observations(t, y, sigma, kind), 0.0, half, FitOptions(block=BATCH))
    inside = t <= half
    cut = fit(prob, Observations(t[inside], y[inside], sigma[inside], kind[inside]), 0.0, half,
              FitOptions(block=BATCH))
    flags = full.residuals["flags"].to_numpy()
    assert np.all((flags[~inside] & OUTSIDE_ARC) > 0) and np.all(flags[inside] == 0)
    assert full.residuals["postfit"][~inside].isna().all()
    assert np.allclose(full.x0, cut.x0, rtol=0, atol=1e-9 * np.abs(cut.x0).max())
