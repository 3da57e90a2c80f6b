"""Batch weighted least squares: against numpy's polyfit, and equal to the SRIF+SRIS
fit when there is no process noise (smoothed epoch = batch epoch estimate)."""

import numpy as np

from odpipe.estimation.least_squares import batch_least_squares
from odpipe.estimation.fit import FitOptions, fit
from estimation_cases import twobody_case


def test_batch_matches_weighted_polyfit_with_vague_apriori():
    rng = np.random.default_rng(0)
    t = np.linspace(0, 10, 50)
    sig = rng.uniform(0.5, 2.0, t.size)
    y = 3.0 - 0.7 * t + 0.05 * t**2 + rng.normal(size=t.size) * sig
    H = np.column_stack([np.ones_like(t), t, t**2])
    sol = batch_least_squares(H, y, sig, np.eye(3) * 1e16)
    coef, cov = np.polyfit(t, y, 2, w=1 / sig, cov="unscaled")
    assert np.allclose(sol.x, coef[::-1], rtol=1e-9)
    assert np.allclose(sol.P, cov[::-1, ::-1], rtol=1e-6)
    # the a priori pulls the solution: with a tight prior on the constant term it stays put
    tight = batch_least_squares(H, y, sig, np.diag([1e-8, 1e16, 1e16]), dx_bar=[2.0, 0, 0])
    assert abs(tight.x[0] - 2.0) < 1e-6


def test_smoother_equals_batch_without_process_noise():
    """Two-body arc, no stochastic accelerations: one filter-smoother pass about the
    a priori reference and the batch solution with partials mapped to the epoch agree."""
    prob, obs, _ = twobody_case(np.random.default_rng(11), maneuvers=(), stochastic=False,
                                dx0=(300.0, -200.0, 100.0, 0.03, -0.02, 0.01))
    reg = prob.registry
    sol = fit(prob, obs, 0.0, 86400.0, FitOptions(block=600.0, max_iter=1))
    x_ref = reg.apriori
    computed, H = prob.predict(0.0, x_ref, np.arange(obs.time.size))
    b = batch_least_squares(H, obs.value - computed, obs.sigma, np.diag(reg.sigma**2))
    dx_fit = sol.smoothed_x[0] - x_ref
    sig = np.sqrt(np.diag(b.P))
    print("max |dx_fit - dx_batch| / sigma", np.max(np.abs(dx_fit - b.x) / sig))
    assert np.max(np.abs(dx_fit - b.x) / sig) < 1e-6
    assert np.max(np.abs(sol.smoothed_P[0] - b.P) / np.outer(sig, sig)) < 1e-6
    post = sol.residuals["postfit"].to_numpy()
    assert np.max(np.abs(post - b.postfit) / obs.sigma) < 1e-5


def test_smoother_equals_batch_linear_to_roundoff():
    """Exactly linear system: filter-smoother and batch agree to ~1e-10 of sigma."""
    from odpipe.estimation.fit import Observations
    from odpipe.estimation.registry import ParameterRegistry
    from estimation_cases import LinearProblem

    rng = np.random.default_rng(4)
    reg = ParameterRegistry()
    reg.add_state("sc", np.zeros(6), 1e3, 1.0)
    reg.add("bias", "bias", 0.0, 5.0)
    A = np.zeros((7, 7))
    A[0:3, 3:6] = np.eye(3)
    t = np.sort(rng.uniform(0, 86400.0, 400))
    Hr = np.column_stack([rng.normal(size=(400, 6)), np.ones(400)])
    prob = LinearProblem(reg, A, Hr, t)
    sig = np.full(400, 2.0)
    y = rng.normal(size=400) * 1e3
    sol = fit(prob, Observations(t, y, sig, np.zeros(400)), 0.0, 86400.0,
              FitOptions(block=3600.0, max_iter=1))
    _, H = prob.predict(0.0, np.zeros(7), np.arange(400))
    b = batch_least_squares(H, y, sig, np.diag(reg.sigma**2))
    s = np.sqrt(np.diag(b.P))
    assert np.max(np.abs(sol.smoothed_x[0] - b.x) / s) < 1e-9
    assert np.max(np.abs(sol.smoothed_P[0] - b.P) / np.outer(s, s)) < 1e-9
